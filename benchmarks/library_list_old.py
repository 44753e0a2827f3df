"""The library list as it was before the SQLite work, kept so that ``library_query.py`` times
the old and the new list in one run on the same database.

Offset paging over the whole ordered query (ids first, rows by id after), a count capped at
10,000, boolean filters written ``NOT "superseded"`` (no index can seek to it on SQLite),
label names and annotator usernames filtered through joins, ``ordering=label`` sorting
every match by the label table's name.
"""

from django.contrib.auth import get_user_model
from rest_framework.exceptions import NotFound
from rest_framework.pagination import PageNumberPagination
from rest_framework.response import Response

from segmentation.api.common.params import bool_param, float_param, int_param
from segmentation.api.common.serializers.library import SegmentSerializer
from segmentation.api.segments import SegmentListView
from segmentation.errors import Invalid
from segmentation.models import LibrarySegment

ORDERINGS = {
    "recent": ("-id",), "duration": ("duration", "id"), "-duration": ("-duration", "-id"),
    "agreement": ("agreement", "id"), "-agreement": ("-agreement", "-id"),
    "label": ("label__name", "id"), "capture": ("capture_id", "start", "id"),
}


class OldSegmentPagination(PageNumberPagination):
    page_size = 50
    page_size_query_param = "page_size"
    max_page_size = 500
    count_cap = 10_000

    def paginate_queryset(self, queryset, request, view=None):
        self.request = request
        size = self.get_page_size(request)
        self.number = int_param(request, self.page_query_param, 1, 1, 1_000_000)
        offset = (self.number - 1) * size
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
            raise NotFound(f"page: there is no page {self.number}")
        return rows

    def get_paginated_response(self, data):
        return Response({"count": self.count, "count_capped": self.capped, "results": data})


def old_segment_query(request):
    segments = LibrarySegment.objects.visible_to(request.user)
    gold = bool_param(request, "gold")
    segments = segments.preferred() if gold is None else segments.filter(is_gold=gold)
    for name, field in (("project", "project_id"), ("capture", "capture_id")):
        value = int_param(request, name, None, 1)
        if value is not None:
            segments = segments.filter(**{field: value})
    annotator = (request.query_params.get("annotator") or "").strip()
    if annotator.isdigit():
        segments = segments.filter(annotator_id=int_param(request, "annotator", None, 1))
    elif annotator:
        if not get_user_model().objects.filter(username=annotator).exists():
            raise Invalid(f"annotator: no user named {annotator[:150]!r}")
        segments = segments.filter(annotator__username=annotator)
    if request.query_params.get("label"):
        segments = segments.filter(label__name=request.query_params["label"])
    for name, lookup, high in (("min_duration", "duration__gte", None),
                               ("max_duration", "duration__lte", None),
                               ("min_agreement", "agreement__gte", 1)):
        value = float_param(request, name, 0, high)
        if value is not None:
            segments = segments.filter(**{lookup: value})
    ordering = request.query_params.get("ordering") or "recent"
    return segments.order_by(*ORDERINGS[ordering])


class OldSegmentListView(SegmentListView):
    def get(self, request):
        segments = old_segment_query(request).select_related("capture", "annotator", "label").defer(
            "descriptor", "profile", "capture__skeleton")
        paginator = OldSegmentPagination()
        page = paginator.paginate_queryset(segments, request, view=self)
        return paginator.get_paginated_response(SegmentSerializer(page, many=True).data)
