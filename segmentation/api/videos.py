"""A capture's reference videos: list and upload (``/api/captures/{id}/videos/``), set the
offset or remove one (``…/videos/{video}/``), and its bytes in ranges (``…/file/``).

Every member of the capture's project sees and plays them; reviewers and admins upload,
align and remove them (``ReferenceVideo.may_manage``); outsiders get 404.
"""

from django.conf import settings
from django.urls import path
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import extend_schema
from rest_framework.parsers import FormParser, MultiPartParser
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import body
from segmentation.api.common.parsers import BoundedJSONParser
from segmentation.api.common.ranges import ranged_response
from segmentation.api.common.serializers.videos import (
    OffsetSerializer,
    VideoListSerializer,
    VideoSerializer,
    VideoUploadedSerializer,
    VideoUploadSerializer,
)
from segmentation.errors import Missing, UploadTooLarge
from segmentation.files.video import CONTAINERS, ffprobe_path
from segmentation.models import ReferenceVideo
from segmentation.queries.access import capture_for
from segmentation.services import videos


def video_for(user, pk, video_id):
    """A video of a capture the user sees, or 404."""
    video = ReferenceVideo.objects.filter(capture=capture_for(user, pk), pk=video_id).first()
    if video is None:
        raise Missing("No such video.")
    return video


class VideosView(APIView):
    parser_classes = [MultiPartParser, FormParser, BoundedJSONParser]

    @extend_schema(responses=VideoListSerializer, operation_id="captures_videos_list")
    def get(self, request, pk):
        capture = capture_for(request.user, pk)
        return Response(VideoListSerializer({
            "may_manage": ReferenceVideo.may_manage(capture.project, request.user),
            "probes": ffprobe_path() is not None,
            "max_mb": settings.CUTROOM_MAX_VIDEO_MB,
            "videos": capture.videos.select_related("uploaded_by", "offset_set_by"),
        }).data)

    @extend_schema(request={"multipart/form-data": VideoUploadSerializer},
                   responses={201: VideoUploadedSerializer, 200: VideoUploadedSerializer})
    def post(self, request, pk):
        capture = capture_for(request.user, pk)
        # Refused before the body is read: who may not upload, and what is too large.
        videos.check_may_manage(capture, request.user)
        length = int(request.META.get("CONTENT_LENGTH") or 0)
        if length > videos.max_video_bytes() + 1024 * 1024:
            raise UploadTooLarge(
                f"file: the upload is {length / 2**20:.1f} MB; the limit for a video is "
                f"{settings.CUTROOM_MAX_VIDEO_MB} MB (CUTROOM_MAX_VIDEO_MB)")
        upload = body(request, VideoUploadSerializer)["file"]
        video, created = videos.do_upload_video(capture, request.user, upload)
        video.duplicate = not created
        return Response(VideoUploadedSerializer(video).data, status=201 if created else 200)


class VideoView(APIView):
    parser_classes = [BoundedJSONParser]

    @extend_schema(responses=VideoSerializer)
    def get(self, request, pk, video_id):
        return Response(VideoSerializer(video_for(request.user, pk, video_id)).data)

    @extend_schema(request=OffsetSerializer, responses=VideoSerializer)
    def patch(self, request, pk, video_id):
        """Save the video's offset against the take (seconds)."""
        video = video_for(request.user, pk, video_id)
        videos.check_may_manage(video.capture, request.user)
        video = videos.do_set_offset(video, request.user, body(request, OffsetSerializer)["offset_s"])
        return Response(VideoSerializer(video).data)

    @extend_schema(request=None, responses={204: None})
    def delete(self, request, pk, video_id):
        videos.do_delete_video(video_for(request.user, pk, video_id), request.user)
        return Response(status=204)


class VideoFileView(APIView):
    @extend_schema(responses={(200, "video/mp4"): OpenApiTypes.BINARY,
                              (206, "video/mp4"): OpenApiTypes.BINARY})
    def get(self, request, pk, video_id):
        """The video's bytes; a ``Range`` header gets a 206 with those bytes (seeking)."""
        video = video_for(request.user, pk, video_id)
        return ranged_response(video.file, video.stored_bytes, CONTAINERS[video.container],
                               request.headers.get("Range"), video.checksum)


videos_path = "captures/<int:pk>/videos/"
urlpatterns = [
    path(videos_path, VideosView.as_view(), name="api-videos"),
    path(videos_path + "<int:video_id>/", VideoView.as_view(), name="api-video"),
    path(videos_path + "<int:video_id>/file/", VideoFileView.as_view(), name="api-video-file"),
]
