"""Captures: upload, list, detail, feature signals, playback frames, detection runs."""

import base64
import math

import numpy as np
from django.conf import settings
from django.db.models import Exists, OuterRef, Prefetch
from django.http import HttpResponseNotModified, StreamingHttpResponse
from drf_spectacular.types import OpenApiTypes
from drf_spectacular.utils import OpenApiParameter, PolymorphicProxySerializer, extend_schema
from rest_framework import mixins, viewsets
from rest_framework.decorators import action
from rest_framework.exceptions import PermissionDenied
from rest_framework.pagination import PageNumberPagination
from rest_framework.parsers import FormParser
from rest_framework.renderers import JSONRenderer
from rest_framework.response import Response

from segmentation import services
from segmentation.api.common.heavy import immutable
from segmentation.api.common.params import body, int_param
from segmentation.api.common.parsers import BoundedJSONParser, UploadParser
from segmentation.api.common.renderers import BinaryRenderer
from segmentation.api.common.serializers.captures import (
    CaptureListSerializer,
    CaptureSerializer,
    FramesSerializer,
    PackedSignalsSerializer,
    RunRequestSerializer,
    RunSerializer,
    SignalsSerializer,
    UploadedSerializer,
    UploadSerializer,
)
from segmentation.errors import Invalid, NotReady, UploadTooLarge
from segmentation.files import storage
from segmentation.models import Capture, DetectionRun, JSONArrayLength, Review
from segmentation.queries.access import project_for


class CapturePagination(PageNumberPagination):
    page_size = 50
    page_size_query_param = "page_size"
    max_page_size = 200


class CaptureViewSet(
    mixins.ListModelMixin,
    mixins.RetrieveModelMixin,
    mixins.CreateModelMixin,
    viewsets.GenericViewSet,
):
    serializer_class = CaptureSerializer
    pagination_class = CapturePagination
    parser_classes = [UploadParser, FormParser, BoundedJSONParser]

    def get_serializer_class(self):
        return CaptureListSerializer if self.action == "list" else super().get_serializer_class()

    def get_queryset(self):
        captures = Capture.objects.visible_to(self.request.user)
        if self.action == "list":
            runs = DetectionRun.objects.defer("candidates", "params", "timings").annotate(
                n_candidates=JSONArrayLength("candidates")
            )
            captures = captures.defer("skeleton").prefetch_related(
                Prefetch("runs", runs), "assignments__annotator", "reviews__annotator"
            )
            captures = captures.annotate(review_started=Exists(Review.objects.filter(capture=OuterRef("pk"))))
        else:
            captures = captures.prefetch_related("runs")
        project = int_param(self.request, "project", None)
        if project is not None:
            captures = captures.filter(project_id=project)
        if self.request.query_params.get("status"):
            captures = captures.filter(status=self.request.query_params["status"])
        if self.request.query_params.get("search"):
            captures = captures.filter(name__icontains=self.request.query_params["search"])
        return captures

    @extend_schema(request={"multipart/form-data": UploadSerializer},
                   responses={201: UploadedSerializer, 200: UploadedSerializer})
    def create(self, request, *args, **kwargs):
        # Refuse an oversized body before reading it.
        length = int(request.META.get("CONTENT_LENGTH") or 0)
        limit = services.captures.max_upload_bytes()
        if length > limit + 1024 * 1024:
            raise UploadTooLarge(
                f"file: the upload is {length / 2**20:.1f} MB; the limit is "
                f"{settings.CUTROOM_MAX_UPLOAD_MB} MB (CUTROOM_MAX_UPLOAD_MB)"
            )
        upload = UploadSerializer(data=request.data)
        upload.is_valid(raise_exception=True)
        data = upload.validated_data
        project = project_for(request.user, data["project"])
        # People uploading through the API are rate-limited; imports by command are not.
        capture, created = services.do_upload_capture(
            project, request.user, data["file"], data.get("asf"), rate_limited=True
        )
        capture.duplicate = not created
        return Response(UploadedSerializer(capture).data, status=201 if created else 200)

    @extend_schema(parameters=[OpenApiParameter("max_points", int),
                               OpenApiParameter("encoding", str, enum=["json", "float32"])],
                   responses=PolymorphicProxySerializer(
                       component_name="SignalsAnswer", resource_type_field_name=None,
                       serializers=[SignalsSerializer, PackedSignalsSerializer]))
    @action(detail=True)
    @immutable(lambda view, request: _signal_identity(view.get_object()))
    def signal(self, request, pk=None):
        capture = self.get_object()
        max_points = int_param(request, "max_points", 2000, 2, 1_000_000)
        encoding = request.query_params.get("encoding", "json")
        if encoding not in SIGNAL_ENCODINGS:
            raise Invalid(f"encoding: must be one of {', '.join(SIGNAL_ENCODINGS)}, got "
                          f"{encoding[:40]!r}")
        run = capture.latest_finished_run()
        out = {"run": run.pk if run else None, "fps": capture.fps, "n_frames": capture.n_frames}
        signals = storage.load_npz(run.signals) if run and run.signals else {}
        out["signals"] = [SIGNAL_ENCODINGS[encoding](name, values, max_points)
                           for name, values in signals.items()]
        answer = SignalsSerializer if encoding == "json" else PackedSignalsSerializer
        return Response(answer(out).data)

    @extend_schema(
        parameters=[OpenApiParameter(p, int) for p in ("start", "stop", "step")],
        responses=FramesSerializer,
    )
    @action(detail=True)
    @immutable(lambda view, request: _frames_identity(view.get_object()))
    def frames(self, request, pk=None):
        capture = self.get_object()
        if capture.status != "ready":
            raise NotReady(f"capture {capture.pk} is {capture.status}; it has no frames yet")
        n = capture.n_frames
        start = int_param(request, "start", 0, 0, n - 1)
        step = int_param(request, "step", 1, 1, n)
        stop = int_param(request, "stop", n, start + 1, n)
        # At most CUTROOM_FRAMES_PER_REQUEST frames, and fewer for a skeleton of many joints
        # (an answer stays a few MB); the client continues from "stop".
        per_request = min(settings.CUTROOM_FRAMES_PER_REQUEST,
                          settings.CUTROOM_JOINT_FRAMES_PER_REQUEST // max(capture.n_joints, 1))
        stop = min(stop, start + max(per_request, 1) * step)
        block = np.ascontiguousarray(storage.load_npy(capture.positions)[start:stop:step], "<f4")
        return Response(FramesSerializer({
            "start": start, "stop": stop, "step": step,
            "n_frames": int(block.shape[0]), "n_joints": int(block.shape[1]),
            "dtype": "float32", "data": base64.b64encode(block.tobytes()).decode("ascii"),
        }).data)

    @extend_schema(
        parameters=[OpenApiParameter("start", int), OpenApiParameter("stop", int)],
        responses={(200, "application/octet-stream"): OpenApiTypes.BINARY},
    )
    # JSON first: an error answers JSON to a client that accepts both.
    @action(detail=True, renderer_classes=[JSONRenderer, BinaryRenderer])
    def poses(self, request, pk=None):
        """Joint positions of frames start .. stop - 1 as one binary answer: little-endian
        float32, shape (stop - start, n_joints, 3), frame after frame, streamed from the
        stored array as it is read (no frame cap, nothing encoded). The range is in the
        ``X-Poses-Start`` and ``X-Poses-Stop`` headers, the joints in ``X-Poses-Joints``."""
        capture = self.get_object()
        if capture.status != "ready":
            raise NotReady(f"capture {capture.pk} is {capture.status}; it has no poses yet")
        n = capture.n_frames
        start = int_param(request, "start", 0, 0, n - 1)
        stop = int_param(request, "stop", n, start + 1, n)
        etag = f'"poses-{POSES_FORMAT}-{capture.pk}-{capture.positions.name}-{start}-{stop}"'
        if request.headers.get("If-None-Match") == etag:
            return HttpResponseNotModified(headers={"ETag": etag, "Cache-Control": "private, no-cache"})
        positions = storage.load_npy(capture.positions)
        frame_bytes = 4 * 3 * positions.shape[1]
        return StreamingHttpResponse(
            storage.float32_blocks(positions, start, stop, max(1, POSES_BLOCK_BYTES // frame_bytes)),
            content_type="application/octet-stream",
            headers={"Content-Length": str((stop - start) * frame_bytes), "ETag": etag,
                     "Cache-Control": "private, no-cache", "X-Poses-Start": str(start),
                     "X-Poses-Stop": str(stop), "X-Poses-Joints": str(positions.shape[1])},
        )

    @extend_schema(request=None, responses={202: CaptureSerializer})
    @action(detail=True, methods=["post"])
    def retry(self, request, pk=None):
        """Queue a failed capture's ingest again from its stored original."""
        capture = self.get_object()
        services.do_retry_capture(capture)
        capture.refresh_from_db()
        return Response(CaptureSerializer(capture).data, status=202)

    @extend_schema(request=None, responses={202: RunSerializer})
    @action(detail=True, methods=["post"])
    def redetect(self, request, pk=None):
        """Detect again with the project's method and newest model (reviewers, admins),
        on a capture nobody has started reviewing."""
        capture = self.get_object()
        if not capture.project.can_see_all_reviews(request.user):
            raise PermissionDenied("Only the project's reviewers and admins can re-detect a capture.")
        run = services.do_redetect(capture, request.user)
        return Response(RunSerializer(run).data, status=202)

    @extend_schema(methods=["GET"], responses=RunSerializer(many=True))
    @extend_schema(methods=["POST"], request=RunRequestSerializer, responses={202: RunSerializer})
    # pagination_class: the runs are one list, not pages (it keeps the schema saying so).
    @action(detail=True, methods=["get", "post"], serializer_class=RunRequestSerializer,
            pagination_class=None)
    def runs(self, request, pk=None):
        capture = self.get_object()
        if request.method == "GET":
            staff = {"sees_all_reviews": capture.project.can_see_all_reviews(request.user)}
            return Response(RunSerializer(capture.runs.all(), many=True, context=staff).data)
        run = services.do_start_run(capture, request.user, **body(request, RunRequestSerializer))
        return Response(RunSerializer(run).data, status=202)


def _signal_identity(capture):
    # A finished run's signals are written once; a newer run is another answer.
    run = capture.latest_finished_run()
    return (run.pk, run.signals.name) if run and run.signals else None


def _frames_identity(capture):
    # Ingest writes a capture's positions once, before it is ready.
    return (capture.pk, capture.positions.name) if capture.status == "ready" else None


def _sampled(name, values, max_points):
    step = max(1, math.ceil(len(values) / max_points))
    sampled = np.asarray(values[::step], dtype=float)
    return {"name": name, "start": 0, "step": step, "values": np.round(sampled, 6).tolist()}


def _sampled_float32(name, values, max_points):
    """As ``_sampled``, the values as base64 little-endian float32 (``data``), as the
    frames are sent: 5.3 bytes a value instead of about 9 as JSON, and nothing for the page
    to parse (an hour at 120 fps, two signals: 4.4 MB instead of 7.7 MB)."""
    step = max(1, math.ceil(len(values) / max_points))
    sampled = np.ascontiguousarray(values[::step], dtype="<f4")
    return {"name": name, "start": 0, "step": step, "dtype": "float32",
            "data": base64.b64encode(sampled.tobytes()).decode("ascii")}


SIGNAL_ENCODINGS = {"json": _sampled, "float32": _sampled_float32}

# The poses answer's layout, named in its ETag: a browser never keeps one across a change.
POSES_FORMAT = "f4le1"
# Bytes of positions copied out of the stored array at a time while a poses answer streams.
POSES_BLOCK_BYTES = 1 << 20
