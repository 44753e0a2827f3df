"""``GET /api/projects/{id}/dashboard/``: a project's review progress, annotators and
agreement (reviewers and admins)."""

from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework import serializers
from rest_framework.exceptions import PermissionDenied
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.serializers.agreement import LabelOverlapSerializer
from segmentation.api.common.serializers.base import NamedRefSerializer
from segmentation.models import Review
from segmentation.queries import dashboard
from segmentation.queries.access import project_for

# The schema's CaptureStateEnum (settings.SPECTACULAR_SETTINGS).
CAPTURE_STATES = dashboard.STATES


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


class DashboardView(APIView):
    @extend_schema(responses=DashboardSerializer)
    def get(self, request, pk):
        project = project_for(request.user, pk)
        if not project.can_see_all_reviews(request.user):
            raise PermissionDenied("Only the project's reviewers and admins see its dashboard.")
        return Response(DashboardSerializer(dashboard.dashboard(project)).data)


urlpatterns = [
    path("projects/<int:pk>/dashboard/", DashboardView.as_view(), name="api-dashboard"),
]
