"""JSON shapes of a capture's reference videos (docs/api.md, "Reference videos")."""

from rest_framework import serializers

from segmentation.api.common.serializers.base import UserRefSerializer
from segmentation.models import ReferenceVideo
from segmentation.models.videos import MAX_OFFSET_S


class VideoSerializer(serializers.ModelSerializer):
    """One video; ``duration`` (s), ``fps``, ``codec`` and the size are null/empty when
    ffprobe was not installed at upload. The video time at take time ``t`` is
    ``t + offset_s``."""

    uploaded_by = UserRefSerializer(read_only=True, allow_null=True)
    offset_set_by = UserRefSerializer(read_only=True, allow_null=True)
    url = serializers.SerializerMethodField()
    content_type = serializers.SerializerMethodField()

    class Meta:
        model = ReferenceVideo
        fields = ["id", "name", "url", "content_type", "container", "codec", "duration", "fps",
                  "width", "height", "stored_bytes", "checksum", "offset_s", "offset_set_by",
                  "offset_set_at", "uploaded_by", "created_at"]
        read_only_fields = fields

    def get_url(self, video) -> str:
        return f"/api/captures/{video.capture_id}/videos/{video.pk}/file/"

    def get_content_type(self, video) -> str:
        return {"mp4": "video/mp4", "webm": "video/webm"}[video.container]


class VideoListSerializer(serializers.Serializer):
    """A capture's videos, and what the caller may do with them."""

    may_manage = serializers.BooleanField(
        help_text="Whether the caller may upload, align and remove videos (reviewers, admins).")
    probes = serializers.BooleanField(
        help_text="Whether the server reads codec, duration and frame rate (ffprobe installed).")
    max_mb = serializers.IntegerField(help_text="The largest video accepted, in MB.")
    videos = VideoSerializer(many=True)


class VideoUploadSerializer(serializers.Serializer):
    file = serializers.FileField(allow_empty_file=True)


class VideoUploadedSerializer(VideoSerializer):
    duplicate = serializers.BooleanField(
        read_only=True, help_text="The capture already had this file (same checksum).")

    class Meta(VideoSerializer.Meta):
        fields = [*VideoSerializer.Meta.fields, "duplicate"]
        read_only_fields = fields


class OffsetSerializer(serializers.Serializer):
    offset_s = serializers.FloatField(min_value=-MAX_OFFSET_S, max_value=MAX_OFFSET_S)
