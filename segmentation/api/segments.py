"""The clip library's segments: the filtered, paged list, one segment, and its exports.

- ``GET /api/segments/?project=&label=&capture=&annotator=<username or id>&min_duration=&max_duration=&min_agreement=&gold=&attribute=<name:value>&ordering=&page=``
  (``attribute`` repeatable: every one must hold)
  (``count`` exact up to 10,000 matches, else 10,000 with ``count_capped``)
- ``GET /api/segments/{id}/``, ``…/export.bvh``, ``…/export.fbx``, ``…/export.glb``
- ``GET /api/segments/export.zip?<same filters>&file_format=bvh|fbx|glb`` (streamed)
- ``GET /api/segments/annotations.{csv|eaf|labelstudio}?<same filters>``: the matching
  segments' labels as annotation files (``files.annotation_exports``)

Annotators see their own segments and gold segments; reviewers and admins everybody's.
"""

from django.http import HttpResponse, StreamingHttpResponse
from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework.exceptions import NotFound
from rest_framework.pagination import PageNumberPagination
from rest_framework.response import Response
from rest_framework.utils.urls import remove_query_param, replace_query_param
from rest_framework.views import APIView

from segmentation.api.common.params import bool_param, float_param, int_param
from segmentation.api.common.serializers.library import SegmentSerializer
from segmentation.errors import Invalid
from segmentation.files import annotation_exports, exports
from segmentation.files.storage import read_take
from segmentation.queries.access import segment_for
from segmentation.queries.library import (
    ListQuery,
    attribute_filter,
    capped_count,
    check_ordering,
    page_ids,
    page_rows,
    user_named,
)
from segmentation.services.attributes import shown_library_values


class SegmentPagination(PageNumberPagination):
    """Page numbers as before, without counting a million rows for each page.

    A page reads one id more than it shows, which says whether there is a next page.
    The count is exact up to ``count_cap`` matches (a count of at most that many rows,
    or none at all on the last page); beyond it ``count`` is the cap and ``count_capped``
    is true, so a page of a huge library costs as much as a page of a small one.

    The query comes as ordered ``Part``s whose concatenation is the list (see
    ``queries.library.ordered_parts``): one, or one per label name when ordered by label, so that each is
    read in its order from an index, and a deep page skips whole parts by counting them
    (capped at what is left to skip) instead of sorting every match.

    The page is its segments' API fields (``page_rows``), not model instances.
    """

    page_size = 50
    page_size_query_param = "page_size"
    max_page_size = 500
    count_cap = 10_000

    def paginate_queryset(self, parts, request, view=None):
        """The page's rows of the list ``parts`` (``ListQuery.parts``) as the API shows them."""
        self.request = request
        size = self.get_page_size(request)
        self.number = int_param(request, self.page_query_param, 1, 1, 1_000_000)
        offset = (self.number - 1) * size
        # The page's ids first (an index can answer that alone, however deep the page),
        # then its rows by id.
        ids = page_ids(parts, offset, size + 1)
        self.has_next = len(ids) > size
        rows = page_rows(ids[:size])
        if rows and not self.has_next:
            self.count, self.capped = offset + len(rows), False
        else:
            cap = max(self.count_cap, offset + size + 1)
            self.count = capped_count(parts, cap)
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


# What a list row shows of a segment (``SegmentSerializer``'s fields), read as columns:
# building a segment, capture, label and user instance per row and serializing them field
# by field cost a page of 50 more CPU than all its queries.
def list_query(request):
    """The ``ListQuery`` of a list or zip request's query string (each parameter checked in
    turn: the first bad one is the error)."""
    params = request.query_params
    asked = {"ordering": check_ordering(params.get("ordering") or "recent"),
             "gold": bool_param(request, "gold"),
             "project": int_param(request, "project", None, 1),
             "capture": int_param(request, "capture", None, 1)}
    annotator = (params.get("annotator") or "").strip()
    if annotator.isdigit():  # a user id (what the API said)
        asked["annotator"] = int_param(request, "annotator", None, 1)
    elif annotator:  # a username (what the page and a person write)
        asked["annotator"] = user_named(annotator)
    for name, high in (("min_duration", None), ("max_duration", None), ("min_agreement", 1)):
        asked[name] = float_param(request, name, 0, high)
    attributes = [attribute_filter(request.user, asked["project"], raw)
                  for raw in params.getlist("attribute") if raw]
    return ListQuery(request.user, label=params.get("label"), attributes=attributes, **asked)


class SegmentListView(APIView):
    pagination_class = SegmentPagination

    @extend_schema(responses=SegmentSerializer(many=True), parameters=[OpenApiParameter(
        "attribute", str, many=True, description="name:value of a segment attribute "
        "(e.g. quality:good, needs cleanup:true); repeat it to ask for several")])
    def get(self, request):
        paginator = self.pagination_class()
        page = paginator.paginate_queryset(list_query(request).parts(), request, view=self)
        values = shown_library_values([row["id"] for row in page])
        for row in page:
            row["attributes"] = values[row["id"]]
        return paginator.get_paginated_response(page)


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
        matching = list_query(request).segments()
        # Only the clips the format writes are counted (the page's progress says how many)
        # and sent; segments of the other kind of take are named in errors.txt.
        segments = exports.writable_in(matching, fmt)
        count = segments.count()
        if count > exports.MAX_EXPORT_SEGMENTS:
            raise Invalid(f"export: the query matches {count} segments; export at most "
                          f"{exports.MAX_EXPORT_SEGMENTS} at a time (narrow the filters)")
        left_out = matching.count() - count
        rows = (segments.select_related("capture", "annotator", "label").defer("descriptor", "profile")
                .prefetch_related("attribute_values__attribute")
                .order_by("capture_id", "start", "id").iterator(chunk_size=200))
        response = StreamingHttpResponse(exports.stream_zip(rows, fmt, left_out),
                                         content_type="application/zip")
        response["Content-Disposition"] = f'attachment; filename="segments-{fmt}.zip"'
        response["X-Clip-Count"] = str(count)
        return response


class SegmentAnnotationsView(APIView):
    @extend_schema(responses={(200, "application/octet-stream"): bytes})
    def get(self, request, form):
        """The matching segments as annotations: one CSV or Label Studio file of every
        take, or a zip of one ELAN document per take (a tier per annotator and gold)."""
        if form not in annotation_exports.FORMATS:
            raise NotFound(f"No export as {form!r}; choose csv, eaf or labelstudio.")
        segments = list_query(request).segments()
        count = segments.count()
        if count > annotation_exports.MAX_SEGMENTS:
            raise Invalid(f"export: the query matches {count} segments; export at most "
                          f"{annotation_exports.MAX_SEGMENTS} at a time (narrow the filters)")
        rows = (segments.select_related("capture", "annotator", "label")
                .defer("descriptor", "profile", "capture__skeleton")
                .order_by("capture_id", "is_gold", "annotator_id", "start", "id"))
        data, content_type, name = annotation_exports.render(
            form, annotation_exports.library_tracks(rows.iterator(chunk_size=500)), "annotations")
        response = HttpResponse(data, content_type=content_type)
        response["Content-Disposition"] = f'attachment; filename="{name}"'
        return response


urlpatterns = [
    path("segments/", SegmentListView.as_view(), name="api-segments"),
    path("segments/export.zip", SegmentZipView.as_view(), name="api-segments-zip"),
    path("segments/annotations.<str:form>", SegmentAnnotationsView.as_view(),
         name="api-segments-annotations"),
    path("segments/<int:pk>/", SegmentView.as_view(), name="api-segment"),
    path("segments/<int:pk>/export.bvh", SegmentBvhView.as_view(), name="api-segment-bvh"),
    path("segments/<int:pk>/export.<str:fmt>", SegmentClipView.as_view(), name="api-segment-clip"),
]
