"""``GET /api/segments/{id}/similar/?k=10``: the library's clips nearest to a segment."""

from django.db.models import Q
from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema
from rest_framework import serializers
from rest_framework.exceptions import NotFound
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import search
from segmentation.api.params import int_param
from segmentation.api.segments import SegmentSerializer
from segmentation.models import LibrarySegment
from segmentation.models.library import STAFF, own


class SimilarSegmentSerializer(SegmentSerializer):
    distance = serializers.FloatField(read_only=True, help_text="Descriptor distance to the segment")

    class Meta(SegmentSerializer.Meta):
        fields = [*SegmentSerializer.Meta.fields, "distance"]


class SimilarSerializer(serializers.Serializer):
    segment = serializers.IntegerField()
    results = SimilarSegmentSerializer(many=True, help_text="Nearest first")


class SimilarView(APIView):
    @extend_schema(responses=SimilarSerializer, parameters=[OpenApiParameter("k", int)])
    def get(self, request, pk):
        k = int_param(request, "k", 10, 1, 100)
        user = request.user
        # One query reads the segment, the user's role in its project and whether that
        # role shows it; the role then decides which clips it may be compared with.
        segment = (LibrarySegment.objects.with_role_of(user).select_related("capture")
                   .only(*search.QUERY_FIELDS).filter(pk=pk)
                   .filter(Q(role__in=STAFF) | Q(role__isnull=False) & own(user)).first())
        if segment is None:
            raise NotFound("No such segment.")
        visible = LibrarySegment.objects.visible_in(segment.project_id, user, segment.role)
        results = []
        for s, d in search.similar(segment, visible.preferred(), k=k):
            if isinstance(s, search.Shown):
                results.append({**s.data, "distance": round(d, 4)})
            else:
                s.distance = round(d, 4)
                results.append(SimilarSegmentSerializer(s).data)
        return Response({"segment": segment.pk, "results": results})


urlpatterns = [
    path("segments/<int:pk>/similar/", SimilarView.as_view(), name="api-segment-similar"),
]
