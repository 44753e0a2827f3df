"""JSON shapes of segment attributes: the project's schema, and setting a value."""

from rest_framework import serializers

from segmentation.api.common.serializers.reviews import VersionSerializer
from segmentation.models.attributes import KINDS, MAX_TEXT


class AttributeSerializer(serializers.Serializer):
    id = serializers.IntegerField(read_only=True)
    name = serializers.CharField(max_length=200)
    kind = serializers.ChoiceField(choices=KINDS)
    options = serializers.ListField(child=serializers.CharField(max_length=200), required=False,
                                    default=list, help_text="a choice's options in order")
    hotkey = serializers.CharField(max_length=1, allow_null=True, required=False, default=None)
    position = serializers.IntegerField(read_only=True)
    in_use = serializers.IntegerField(read_only=True, required=False,
                                      help_text="segments of reviews and gold versions carrying it")


class AttributeChangeSerializer(serializers.Serializer):
    name = serializers.CharField(max_length=200, required=False)
    kind = serializers.ChoiceField(choices=KINDS, required=False)
    options = serializers.ListField(child=serializers.CharField(max_length=200), required=False)
    hotkey = serializers.CharField(max_length=1, allow_null=True, required=False)


class AttributeValueField(serializers.JSONField):
    """A choice's option, free text or true/false; null clears."""


class SetAttributeSerializer(VersionSerializer):
    name = serializers.CharField(max_length=200)
    value = AttributeValueField(allow_null=True, help_text=f"an option, text (at most {MAX_TEXT} "
                                "characters) or true/false as the attribute's kind; null clears")
