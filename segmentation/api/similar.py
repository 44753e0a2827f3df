"""``GET /api/segments/{id}/similar/?k=10``: the library's clips nearest to a segment."""

from django.db.models import Q
from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import serializers
from rest_framework.exceptions import NotFound
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import int_param
from segmentation.api.common.serializers.library import SegmentSerializer
from segmentation.db.statements import Statement
from segmentation.models import Capture, LibrarySegment
from segmentation.models.library import STAFF, own
from segmentation.services.attributes import shown_library_values
from segmentation.similar import search
from segmentation.similar.pools import Scope


class SimilarSegmentSerializer(SegmentSerializer):
    distance = serializers.FloatField(read_only=True, help_text="Descriptor distance to the segment")

    class Meta(SegmentSerializer.Meta):
        fields = [*SegmentSerializer.Meta.fields, "distance"]


class SimilarSerializer(serializers.Serializer):
    segment = serializers.IntegerField()
    results = SimilarSegmentSerializer(many=True, help_text="Nearest first")


def _segment_query(key, pk, user_id):
    """The segment a search starts from, with the caller's role in its project, if that
    role shows it to them."""
    return (LibrarySegment.objects.with_role_of(user_id).filter(pk=pk)
            .filter(Q(role__in=STAFF) | Q(role__isnull=False) & own(user_id))
            .values_list("project_id", "capture_id", "start", "stop", "descriptor",
                         "descriptor_shape", "capture__skeleton", "role"))


# One query reads the segment, the user's role in its project and whether that role shows
# it (compiled once: ``segmentation.db.statements``).
SEGMENT = Statement(_segment_query)


class SimilarView(APIView):
    @extend_schema(responses=SimilarSerializer, parameters=[OpenApiParameter("k", int)])
    def get(self, request, pk):
        k = int_param(request, "k", 10, 1, 100)
        user = request.user
        found = SEGMENT.rows(LibrarySegment.objects.db, None, pk=pk, user_id=user.pk)
        if not found:
            raise NotFound("No such segment.")
        project_id, capture_id, start, stop, descriptor, shape, skeleton, role = found[0]
        segment = LibrarySegment(pk=pk, project_id=project_id, start=start, stop=stop,
                                 descriptor=descriptor, descriptor_shape=shape)
        segment.capture = Capture(pk=capture_id, skeleton=skeleton)
        # The role then decides which clips it may be compared with.
        results, shown = [], []
        for s, d in search.similar(segment, Scope(user.pk, role), k=k):
            if isinstance(s, search.Shown):
                results.append({**s.data, "distance": round(d, 4)})
                shown.append(results[-1])
            else:
                s.distance = round(d, 4)
                results.append(SimilarSegmentSerializer(s).data)
        # Rows shown from the index's columns get their attribute values in one query, as
        # the serializer gives them to the others.
        values = shown_library_values([row["id"] for row in shown]) if shown else {}
        for row in shown:
            row["attributes"] = values[row["id"]]
        return Response({"segment": pk, "results": results})


urlpatterns = [
    path("segments/<int:pk>/similar/", SimilarView.as_view(), name="api-segment-similar"),
]
