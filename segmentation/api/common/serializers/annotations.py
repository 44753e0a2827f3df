"""Shapes of the annotation import and export (``api/annotations.py``)."""

from rest_framework import serializers

from motionlib.io.annotations import FORMATS
from segmentation.api.common.serializers.reviews import ReviewSerializer

TARGETS = ("review", "gold")


class InspectSerializer(serializers.Serializer):
    file = serializers.FileField(help_text="CSV, ELAN .eaf or Label Studio JSON export")
    format = serializers.ChoiceField(choices=list(FORMATS), required=False,
                                     allow_blank=True, help_text="by the extension when absent")
    source = serializers.CharField(required=False, allow_blank=True, max_length=500,
                                   help_text="the tier, annotation or annotator to import")
    unit = serializers.ChoiceField(choices=["seconds", "frames"], default="seconds",
                                   help_text="what Label Studio's start/end count")
    target = serializers.ChoiceField(choices=TARGETS, default="review")


class ImportSerializer(InspectSerializer):
    mapping = serializers.CharField(required=False, allow_blank=True, max_length=100_000,
                                    help_text="JSON object: file label -> project label")
    version = serializers.IntegerField(min_value=0, help_text="the review's version, or the "
                                       "gold version (0 when there is none)")


class GoldImportedSerializer(serializers.Serializer):
    cuts = serializers.ListField(child=serializers.IntegerField())
    labels = serializers.ListField(child=serializers.CharField(allow_null=True))
    version = serializers.IntegerField()


class ImportedSerializer(serializers.Serializer):
    review = ReviewSerializer(allow_null=True, help_text="the review as imported (target review)")
    gold = GoldImportedSerializer(allow_null=True, help_text="the gold version as imported "
                                  "(target gold)")


class FileSegmentSerializer(serializers.Serializer):
    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    label = serializers.CharField(allow_null=True)
    where = serializers.CharField()


class FileLabelSerializer(serializers.Serializer):
    name = serializers.CharField()
    count = serializers.IntegerField()
    known = serializers.BooleanField(help_text="a label in use of the project")
    suggestion = serializers.CharField(allow_null=True, help_text="the label in use that "
                                       "differs only in case and spaces")


class InspectionSerializer(serializers.Serializer):
    file = serializers.CharField()
    format = serializers.CharField()
    sources = serializers.ListField(child=serializers.CharField())
    source = serializers.CharField(allow_null=True)
    chosen = serializers.BooleanField(help_text="false while the file has several sources "
                                      "and none was chosen")
    other_takes = serializers.IntegerField(help_text="annotations of the chosen source about "
                                           "other takes, left out")
    segments = FileSegmentSerializer(many=True)
    labels = FileLabelSerializer(many=True)
    project_labels = serializers.ListField(child=serializers.CharField())
