"""JSON shapes of the clip library: a library segment."""

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from segmentation.api.common.serializers.base import NamedRefSerializer, UserRefSerializer
from segmentation.files import exports
from segmentation.models import LibrarySegment
from segmentation.services.attributes import shown_library_values


class SegmentSerializer(serializers.ModelSerializer):
    capture = serializers.SerializerMethodField()
    annotator = serializers.SerializerMethodField()
    label = serializers.CharField(source="label.name")
    color = serializers.SerializerMethodField()
    gold = serializers.BooleanField(source="is_gold")
    fps = serializers.FloatField(source="capture.fps")
    export_formats = serializers.SerializerMethodField()
    attributes = serializers.SerializerMethodField()

    class Meta:
        model = LibrarySegment
        fields = ["id", "project", "capture", "review", "annotator", "gold", "superseded",
                  "label", "color", "start", "stop", "fps", "duration", "agreement",
                  "export_formats", "attributes"]

    @extend_schema_field(NamedRefSerializer)
    def get_capture(self, s):
        return {"id": s.capture_id, "name": s.capture.name}

    @extend_schema_field(UserRefSerializer(allow_null=True))
    def get_annotator(self, s):
        return {"id": s.annotator_id, "username": s.annotator.username} if s.annotator_id else None

    def get_export_formats(self, s) -> list[str]:
        return exports.formats_for(s.capture)

    def get_attributes(self, s) -> dict:
        """The segment's attribute values by attribute name."""
        return shown_library_values([s.pk])[s.pk]

    def get_color(self, s) -> str:
        return s.label.color if s.label_id else "#888888"
