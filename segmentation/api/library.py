"""The clip library, agreement, adjudication and the project dashboard.

- ``GET /api/segments/?project=&label=&capture=&annotator=<username or id>&min_duration=&max_duration=&min_agreement=&gold=&ordering=&page=``
  (``count`` exact up to 10,000 matches, else 10,000 with ``count_capped``)
- ``GET /api/segments/{id}/``, ``…/export.bvh``, ``…/export.fbx``, ``…/export.glb``,
  ``…/similar/?k=10``
- ``GET /api/segments/export.zip?<same filters>&file_format=bvh|fbx|glb`` (streamed)
- ``GET /api/captures/{id}/agreement/?tolerance=0.25`` (reviewers and admins)
- ``GET/PUT /api/captures/{id}/adjudication/`` (reviewers and admins)
- ``GET /api/projects/{id}/dashboard/`` (reviewers and admins)

Who sees what: annotators see their own segments and gold segments; agreement,
adjudication and the dashboard compare everybody's reviews, so for annotators they do not
exist (404, like any object the caller may not see).
"""

from django.contrib.auth import get_user_model
from django.http import HttpResponse, StreamingHttpResponse
from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema, extend_schema_field
from rest_framework import serializers
from rest_framework.exceptions import NotFound, PermissionDenied
from rest_framework.pagination import PageNumberPagination
from rest_framework.response import Response
from rest_framework.utils.urls import remove_query_param, replace_query_param
from rest_framework.views import APIView

from segmentation import agreement, dashboard, exports, search
from segmentation.api.captures import capture_for
from segmentation.api.params import body, bool_param, float_param, int_param
from segmentation.api.projects import project_for
from segmentation.api.serializers import (
    DetailSerializer,
    NamedRefSerializer,
    UserRefSerializer,
)
from segmentation.errors import Invalid
from segmentation.models import Adjudication, LibrarySegment, Review
from segmentation.services.gold import do_save_gold
from segmentation.storage import read_take

# The schema's CaptureStateEnum (settings.SPECTACULAR_SETTINGS).
CAPTURE_STATES = dashboard.STATES

ORDERINGS = {
    "recent": ("-id",), "duration": ("duration", "id"), "-duration": ("-duration", "-id"),
    "agreement": ("agreement", "id"), "-agreement": ("-agreement", "-id"),
    "label": ("label_name", "id"), "capture": ("capture_id", "start", "id"),
}


class SegmentPagination(PageNumberPagination):
    """Page numbers as before, without counting a million rows for each page.

    A page reads one id more than it shows, which says whether there is a next page.
    The count is exact up to ``count_cap`` matches (a count of at most that many rows,
    or none at all on the last page); beyond it ``count`` is the cap and ``count_capped``
    is true, so a page of a huge library costs as much as a page of a small one.
    """

    page_size = 50
    page_size_query_param = "page_size"
    max_page_size = 500
    count_cap = 10_000

    def paginate_queryset(self, queryset, request, view=None):
        self.request = request
        size = self.get_page_size(request)
        self.number = int_param(request, self.page_query_param, 1, 1, 1_000_000)
        offset = (self.number - 1) * size
        # The page's ids first (an index can answer that alone, however deep the page),
        # then its rows by id.
        ids = list(queryset.values_list("id", flat=True)[offset:offset + size + 1])
        self.has_next = len(ids) > size
        found = queryset.order_by().in_bulk(ids[:size])
        rows = [found[pk] for pk in ids[:size] if pk in found]
        if rows and not self.has_next:
            self.count, self.capped = offset + len(rows), False
        else:
            cap = max(self.count_cap, offset + size + 1)
            self.count = queryset.order_by()[:cap + 1].count()
            self.capped = self.count > cap
            self.count = min(self.count, cap)
        if not rows and self.number > 1:
            raise NotFound(f"page: there is no page {self.number}; the query matches "
                           f"{self.count} segment(s)")
        return rows

    def get_next_link(self):
        if not self.has_next:
            return None
        return replace_query_param(self.request.build_absolute_uri(), self.page_query_param,
                                   self.number + 1)

    def get_previous_link(self):
        if self.number == 1:
            return None
        url = self.request.build_absolute_uri()
        if self.number == 2:
            return remove_query_param(url, self.page_query_param)
        return replace_query_param(url, self.page_query_param, self.number - 1)

    def get_paginated_response(self, data):
        return Response({"count": self.count, "count_capped": self.capped,
                         "next": self.get_next_link(), "previous": self.get_previous_link(),
                         "results": data})

    def get_paginated_response_schema(self, schema):
        page = super().get_paginated_response_schema(schema)
        page["properties"]["count_capped"] = {"type": "boolean"}
        return page


class SegmentSerializer(serializers.ModelSerializer):
    capture = serializers.SerializerMethodField()
    annotator = serializers.SerializerMethodField()
    label = serializers.CharField(source="label_name")
    color = serializers.SerializerMethodField()
    gold = serializers.BooleanField(source="is_gold")
    fps = serializers.FloatField(source="capture.fps")

    class Meta:
        model = LibrarySegment
        fields = ["id", "project", "capture", "review", "annotator", "gold", "superseded",
                  "label", "color", "start", "stop", "fps", "duration", "agreement"]

    @extend_schema_field(NamedRefSerializer)
    def get_capture(self, s):
        return {"id": s.capture_id, "name": s.capture.name}

    @extend_schema_field(UserRefSerializer(allow_null=True))
    def get_annotator(self, s):
        return {"id": s.annotator_id, "username": s.annotator.username} if s.annotator_id else None

    def get_color(self, s) -> str:
        return s.label.color if s.label_id else "#888888"


class SimilarSegmentSerializer(SegmentSerializer):
    distance = serializers.FloatField(read_only=True, help_text="Descriptor distance to the segment")

    class Meta(SegmentSerializer.Meta):
        fields = [*SegmentSerializer.Meta.fields, "distance"]


class SimilarSerializer(serializers.Serializer):
    segment = serializers.IntegerField()
    results = SimilarSegmentSerializer(many=True, help_text="Nearest first")


class SpanSerializer(serializers.Serializer):
    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    label = serializers.CharField(allow_null=True)


class AgreementReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = UserRefSerializer()
    cuts = serializers.IntegerField(help_text="How many cuts it keeps")
    submitted_at = serializers.DateTimeField(allow_null=True)


class PairSideSerializer(serializers.Serializer):
    review = serializers.IntegerField()
    annotator = serializers.CharField()


class PairSerializer(serializers.Serializer):
    a = PairSideSerializer()
    b = PairSideSerializer()
    precision = serializers.FloatField(allow_null=True)
    recall = serializers.FloatField(allow_null=True)
    f1 = serializers.FloatField(allow_null=True)
    matched = serializers.IntegerField()
    kappa = serializers.FloatField(allow_null=True)


class LabelMeasureSerializer(serializers.Serializer):
    method = serializers.ChoiceField(choices=["cohen_kappa", "krippendorff_alpha"], allow_null=True)
    value = serializers.FloatField(allow_null=True)


class LabelOverlapSerializer(serializers.Serializer):
    label = serializers.CharField()
    overlap = serializers.FloatField(allow_null=True)
    frames = serializers.IntegerField()


class AgreementSerializer(serializers.Serializer):
    """Agreement of a capture's submitted reviews (measures null where undefined)."""

    capture = serializers.IntegerField()
    tolerance_s = serializers.FloatField()
    n_reviews = serializers.IntegerField()
    reviews = AgreementReviewSerializer(many=True)
    pairs = PairSerializer(many=True)
    boundary_f1 = serializers.FloatField(allow_null=True)
    labels = LabelMeasureSerializer()
    alpha = serializers.FloatField(allow_null=True)
    per_label = LabelOverlapSerializer(many=True)


class GoldBodySerializer(serializers.Serializer):
    """The capture's gold version as stored."""

    version = serializers.IntegerField()
    cuts = serializers.ListField(child=serializers.IntegerField())
    labels = serializers.ListField(child=serializers.CharField(allow_null=True))
    segments = SpanSerializer(many=True)
    adjudicator = serializers.CharField(allow_null=True)
    source_review = serializers.IntegerField(allow_null=True)
    updated_at = serializers.DateTimeField()


class AdjudicationCaptureSerializer(NamedRefSerializer):
    fps = serializers.FloatField(allow_null=True)
    n_frames = serializers.IntegerField(allow_null=True)
    project = serializers.IntegerField()


class AdjudicationLabelSerializer(serializers.Serializer):
    name = serializers.CharField()
    color = serializers.CharField()
    hotkey = serializers.CharField(allow_null=True)


class AdjudicationReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = UserRefSerializer()
    status = serializers.ChoiceField(choices=Review.STATUSES)
    cuts = serializers.ListField(child=serializers.IntegerField())
    segments = SpanSerializer(many=True)


class AdjudicationSerializer(serializers.Serializer):
    capture = AdjudicationCaptureSerializer()
    labels = AdjudicationLabelSerializer(many=True)
    reviews = AdjudicationReviewSerializer(many=True)
    gold = GoldBodySerializer(allow_null=True)
    agreement = AgreementSerializer()


class StaleGoldSerializer(DetailSerializer):
    """409: the gold version changed since the one the edit was based on."""

    gold = GoldBodySerializer(allow_null=True)


class CaptureStatesSerializer(serializers.Serializer):
    unreviewed = serializers.IntegerField()
    in_review = serializers.IntegerField()
    agreed = serializers.IntegerField()
    adjudicated = serializers.IntegerField()


class DashboardReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = serializers.CharField()
    status = serializers.ChoiceField(choices=Review.STATUSES)


class DashboardCaptureSerializer(NamedRefSerializer):
    state = serializers.ChoiceField(choices=CAPTURE_STATES)
    reviews = serializers.IntegerField()
    submitted = serializers.IntegerField()
    boundary_f1 = serializers.FloatField(allow_null=True)
    label_agreement = serializers.FloatField(allow_null=True)
    assigned = serializers.ListField(child=serializers.CharField())
    review_states = DashboardReviewSerializer(many=True)


class AnnotatorSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    username = serializers.CharField()
    submitted = serializers.IntegerField()
    in_progress = serializers.IntegerField()
    edits = serializers.DictField(child=serializers.IntegerField(), help_text="By audit-log action")
    edits_total = serializers.IntegerField()
    edits_per_review = serializers.FloatField(allow_null=True)
    median_minutes_per_review = serializers.FloatField(allow_null=True)


class ProjectLabelSerializer(LabelOverlapSerializer):
    captures = serializers.IntegerField()


class LibraryCountsSerializer(serializers.Serializer):
    total = serializers.IntegerField()
    gold = serializers.IntegerField()


class DashboardSerializer(serializers.Serializer):
    project = serializers.IntegerField()
    states = CaptureStatesSerializer()
    captures = DashboardCaptureSerializer(many=True)
    annotators = AnnotatorSerializer(many=True)
    labels = ProjectLabelSerializer(many=True)
    library = LibraryCountsSerializer()


def segment_query(request):
    """The caller's visible segments filtered by the query string (shared by list and zip)."""
    segments = LibrarySegment.objects.visible_to(request.user)
    gold = bool_param(request, "gold")
    if gold is None:
        segments = segments.preferred()
    else:
        segments = segments.filter(is_gold=gold)
    for name, field in (("project", "project_id"), ("capture", "capture_id")):
        value = int_param(request, name, None, 1)
        if value is not None:
            segments = segments.filter(**{field: value})
    annotator = (request.query_params.get("annotator") or "").strip()
    if annotator:
        # A username (what the page and a person write) or a user id (what the API said).
        field = "annotator_id" if annotator.isdigit() else "annotator__username"
        if field == "annotator__username" and not get_user_model().objects.filter(
                username=annotator).exists():
            raise Invalid(f"annotator: no user named {annotator!r}")
        segments = segments.filter(**{field: annotator})
    if request.query_params.get("label"):
        segments = segments.filter(label_name=request.query_params["label"])
    for name, lookup, high in (("min_duration", "duration__gte", None),
                               ("max_duration", "duration__lte", None),
                               ("min_agreement", "agreement__gte", 1)):
        value = float_param(request, name, 0, high)
        if value is not None:
            segments = segments.filter(**{lookup: value})
    ordering = request.query_params.get("ordering") or "recent"
    if ordering not in ORDERINGS:
        raise Invalid(f"ordering: must be one of {', '.join(ORDERINGS)}, got {ordering!r}")
    return segments.order_by(*ORDERINGS[ordering])


def segment_for(user, pk):
    segment = (LibrarySegment.objects.visible_to(user).select_related("capture", "annotator", "label")
               .filter(pk=pk).first())
    if segment is None:
        raise NotFound("No such segment.")
    return segment


class SegmentListView(APIView):
    pagination_class = SegmentPagination

    @extend_schema(responses=SegmentSerializer(many=True))
    def get(self, request):
        segments = segment_query(request).select_related("capture", "annotator", "label").defer(
            "descriptor", "profile", "capture__skeleton")
        paginator = self.pagination_class()
        page = paginator.paginate_queryset(segments, request, view=self)
        return paginator.get_paginated_response(SegmentSerializer(page, many=True).data)


class SegmentView(APIView):
    @extend_schema(responses=SegmentSerializer)
    def get(self, request, pk):
        return Response(SegmentSerializer(segment_for(request.user, pk)).data)


class SegmentBvhView(APIView):
    @extend_schema(responses={(200, "text/plain"): str})
    def get(self, request, pk):
        segment = segment_for(request.user, pk)
        text = exports.bvh_text(read_take(segment.capture), segment)
        response = HttpResponse(text, content_type="application/octet-stream")
        response["Content-Disposition"] = f'attachment; filename="{exports.file_name(segment)}"'
        return response


class SegmentClipView(APIView):
    """``…/export.fbx`` and ``…/export.glb``: the segment as FBX or glTF binary."""

    @extend_schema(responses={(200, "application/octet-stream"): bytes})
    def get(self, request, pk, fmt):
        fmt = exports.check_format(fmt)
        segment = segment_for(request.user, pk)
        capture = segment.capture
        take = read_take(capture)
        [(_, name, data)] = exports.clip_files(capture, take, [segment], fmt)
        response = HttpResponse(data, content_type=exports.CONTENT_TYPES[fmt])
        response["Content-Disposition"] = f'attachment; filename="{name}"'
        # What the manifest's "unit" says for a clip in a zip (docs/exports.md).
        response["X-Length-Unit"] = exports.unit_text(take, fmt)
        return response


class SegmentZipView(APIView):
    @extend_schema(responses={(200, "application/zip"): bytes},
                   parameters=[OpenApiParameter("file_format", str,
                                                enum=list(exports.EXPORT_FORMATS),
                                                description="clip format (default bvh)")])
    def get(self, request):
        # Not "format": DRF reads that one to pick a renderer.
        fmt = exports.check_format(request.query_params.get("file_format"))
        segments = segment_query(request)
        count = segments.count()
        if count > exports.MAX_EXPORT_SEGMENTS:
            raise Invalid(f"export: the query matches {count} segments; export at most "
                          f"{exports.MAX_EXPORT_SEGMENTS} at a time (narrow the filters)")
        rows = (segments.select_related("capture", "annotator").defer("descriptor", "profile")
                .order_by("capture_id", "start", "id").iterator(chunk_size=200))
        response = StreamingHttpResponse(exports.stream_zip(rows, fmt),
                                         content_type="application/zip")
        response["Content-Disposition"] = f'attachment; filename="segments-{fmt}.zip"'
        return response


class SimilarView(APIView):
    @extend_schema(responses=SimilarSerializer, parameters=[OpenApiParameter("k", int)])
    def get(self, request, pk):
        k = int_param(request, "k", 10, 1, 100)
        # One membership lookup for both the segment and the clips it may be compared with.
        visible = LibrarySegment.objects.visible_to(request.user)
        segment = visible.select_related("capture", "annotator", "label").filter(pk=pk).first()
        if segment is None:
            raise NotFound("No such segment.")
        found = search.similar(segment, visible.preferred(), k=k)
        for s, d in found:
            s.distance = round(d, 4)
        return Response(SimilarSerializer({"segment": segment.pk, "results": [s for s, _ in found]}).data)


def staff_capture(user, pk):
    """A capture whose project the user reviews or administers; 404 for outsiders, 403
    (saying why) for an annotator, who sees the capture anyway."""
    capture = capture_for(user, pk)
    if not capture.project.can_see_all_reviews(user):
        raise PermissionDenied("Only the project's reviewers and admins see agreement and "
                               "adjudicate; you annotate in this project.")
    return capture


class AgreementView(APIView):
    @extend_schema(responses=AgreementSerializer,
                   parameters=[OpenApiParameter("tolerance", float, description="seconds (default 0.25)")])
    def get(self, request, pk):
        capture = staff_capture(request.user, pk)
        tolerance = float_param(request, "tolerance", 0, 10)
        tolerance = agreement.DEFAULT_TOLERANCE_S if tolerance is None else tolerance
        return Response(AgreementSerializer(agreement.capture_agreement(capture, tolerance)).data)


class GoldSerializer(serializers.Serializer):
    cuts = serializers.ListField(child=serializers.IntegerField())
    labels = serializers.ListField(child=serializers.CharField(allow_null=True))
    version = serializers.IntegerField(min_value=0)
    source_review = serializers.IntegerField(required=False, allow_null=True)


def gold_body(gold):
    if gold is None:
        return None
    return {
        "version": gold.version, "cuts": gold.cuts, "labels": gold.labels,
        "segments": [{"start": a, "stop": b, "label": c} for a, b, c in gold.segments()],
        "adjudicator": gold.adjudicator.username if gold.adjudicator else None,
        "source_review": gold.source_review_id, "updated_at": gold.updated_at,
    }


def adjudication_body(capture):
    reviews = Review.objects.filter(capture=capture).select_related("annotator", "capture")
    reviews = reviews.prefetch_related("cuts", "segment_labels__label").order_by("id")
    gold = Adjudication.objects.select_related("adjudicator").filter(capture=capture).first()
    return {
        "capture": {"id": capture.pk, "name": capture.name, "fps": capture.fps,
                    "n_frames": capture.n_frames, "project": capture.project_id},
        "labels": [{"name": x.name, "color": x.color, "hotkey": x.hotkey}
                   for x in capture.project.labels.all()],
        "reviews": [
            {"id": r.pk, "annotator": {"id": r.annotator_id, "username": r.annotator.username},
             "status": r.status, "cuts": agreement.review_cuts(r),
             "segments": [{"start": a, "stop": b, "label": c}
                          for a, b, c in agreement.review_segments(r)]}
            for r in reviews
        ],
        "gold": gold_body(gold),
        "agreement": agreement.capture_agreement(capture),
    }


class AdjudicationView(APIView):
    @extend_schema(responses=AdjudicationSerializer)
    def get(self, request, pk):
        return Response(AdjudicationSerializer(adjudication_body(staff_capture(request.user, pk))).data)

    @extend_schema(request=GoldSerializer, responses={200: AdjudicationSerializer, 409: StaleGoldSerializer})
    def put(self, request, pk):
        capture = staff_capture(request.user, pk)
        data = body(request, GoldSerializer)
        source = None
        if data.get("source_review") is not None:
            source = Review.objects.filter(pk=data["source_review"], capture=capture,
                                           status="submitted").first()
            if source is None:
                raise Invalid(f"source_review: review {data['source_review']} is not a "
                              "submitted review of this capture")
        do_save_gold(capture, request.user, data["cuts"], data["labels"], data["version"], source)
        return Response(AdjudicationSerializer(adjudication_body(capture)).data)


class DashboardView(APIView):
    @extend_schema(responses=DashboardSerializer)
    def get(self, request, pk):
        project = project_for(request.user, pk)
        if not project.can_see_all_reviews(request.user):
            raise PermissionDenied("Only the project's reviewers and admins see its dashboard.")
        return Response(DashboardSerializer(dashboard.dashboard(project)).data)


urlpatterns = [
    path("segments/", SegmentListView.as_view(), name="api-segments"),
    path("segments/export.zip", SegmentZipView.as_view(), name="api-segments-zip"),
    path("segments/<int:pk>/", SegmentView.as_view(), name="api-segment"),
    path("segments/<int:pk>/export.bvh", SegmentBvhView.as_view(), name="api-segment-bvh"),
    path("segments/<int:pk>/export.<str:fmt>", SegmentClipView.as_view(), name="api-segment-clip"),
    path("segments/<int:pk>/similar/", SimilarView.as_view(), name="api-segment-similar"),
    path("captures/<int:pk>/agreement/", AgreementView.as_view(), name="api-agreement"),
    path("captures/<int:pk>/adjudication/", AdjudicationView.as_view(), name="api-adjudication"),
    path("projects/<int:pk>/dashboard/", DashboardView.as_view(), name="api-dashboard"),
]
