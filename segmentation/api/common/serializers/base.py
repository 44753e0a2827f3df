"""Fields and small shapes every noun's serializers share: bounded text, a person, a
named record, a sentence, a record's error."""

from rest_framework import serializers


class Text(serializers.CharField):
    """A free-text request field with its bound (see ``segmentation.limits``): a longer
    value is refused saying the bound and its length, as the services do."""

    def __init__(self, max_length, **kwargs):
        messages = kwargs.pop("error_messages", {})
        messages.setdefault("max_length",
                            "must be at most {max_length} characters, got %(show_value)d")
        super().__init__(max_length=max_length, error_messages=messages, **kwargs)


class UserRefSerializer(serializers.Serializer):
    """A person as other records name them."""

    id = serializers.IntegerField()
    username = serializers.CharField()


class NamedRefSerializer(serializers.Serializer):
    """A capture or project as other records name them."""

    id = serializers.IntegerField()
    name = serializers.CharField()


class DetailSerializer(serializers.Serializer):
    """An answer that is only a sentence for the user."""

    detail = serializers.CharField()


class ErrorField(serializers.CharField):
    """A record's error text: null, not "", while it has none."""

    def __init__(self, **kwargs):
        super().__init__(read_only=True, allow_null=True, **kwargs)

    def to_representation(self, value):
        return value or None
