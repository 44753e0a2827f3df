"""Assignments (reviewers and admins hand captures to annotators), each annotator's queue,
and returning a submitted review to its annotator."""

from django.contrib.auth import get_user_model
from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import OpenApiParameter, extend_schema, extend_schema_field
from rest_framework import serializers
from rest_framework.exceptions import PermissionDenied
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import body, int_param
from segmentation.api.common.serializers.base import NamedRefSerializer, Text
from segmentation.api.common.serializers.reviews import ReviewSerializer
from segmentation.limits import USERNAME_LENGTH, text_limit
from segmentation.models import Assignment, Project, Review
from segmentation.queries.access import capture_for, project_for
from segmentation.services import assignments as service
from segmentation.services import queue as queues
from segmentation.services import returns

# The schema's QueueStateEnum (settings.SPECTACULAR_SETTINGS).
QUEUE_STATES = queues.QUEUE_STATES


class AssignmentSerializer(serializers.ModelSerializer):
    capture = serializers.SerializerMethodField()
    annotator = serializers.CharField(source="annotator.username")
    assigned_by = serializers.CharField(source="assigned_by.username", default=None)
    state = serializers.SerializerMethodField()

    class Meta:
        model = Assignment
        fields = ["id", "capture", "annotator", "assigned_by", "created_at", "state"]

    @extend_schema_field(NamedRefSerializer)
    def get_capture(self, a):
        return {"id": a.capture_id, "name": a.capture.name}

    @extend_schema_field(serializers.ChoiceField(choices=QUEUE_STATES))
    def get_state(self, a):
        """assigned (no review yet), in_progress, returned or submitted."""
        review = next((r for r in a.capture.reviews.all() if r.annotator_id == a.annotator_id), None)
        return review.status if review else "assigned"


class AssignRequest(serializers.Serializer):
    captures = serializers.ListField(child=serializers.IntegerField(), allow_empty=False)
    annotators = serializers.ListField(child=Text(USERNAME_LENGTH), allow_empty=False)
    per_capture = serializers.IntegerField(required=False, allow_null=True, default=None,
                                           help_text="Each capture to this many of the annotators, "
                                                     "spread evenly; omitted: to all of them.")


class ReassignRequest(serializers.Serializer):
    annotator = Text(USERNAME_LENGTH)


class ReturnRequest(serializers.Serializer):
    comment = Text(text_limit(Review, "return_comment"), allow_blank=True)


class QueueCaptureSerializer(NamedRefSerializer):
    project = serializers.IntegerField()
    duration = serializers.FloatField(allow_null=True)
    n_frames = serializers.IntegerField(allow_null=True)
    n_candidates = serializers.IntegerField(allow_null=True, help_text="null: no finished run")


class QueueReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    version = serializers.IntegerField()
    submitted_at = serializers.DateTimeField(allow_null=True)
    return_comment = serializers.CharField(allow_null=True)
    returned_at = serializers.DateTimeField(allow_null=True)


class QueueItemSerializer(serializers.Serializer):
    capture = QueueCaptureSerializer()
    state = serializers.ChoiceField(choices=QUEUE_STATES)
    assigned = serializers.BooleanField()
    since = serializers.DateTimeField()
    review = QueueReviewSerializer(allow_null=True)


def assigning_project(request, pk):
    """A project the caller may assign in (reviewer or admin), 403 for annotators."""
    project = project_for(request.user, pk)
    if not project.can_see_all_reviews(request.user):
        raise PermissionDenied("Only the project's reviewers and admins assign captures.")
    return project


class AssignmentsView(APIView):
    @extend_schema(responses=AssignmentSerializer(many=True),
                   parameters=[OpenApiParameter("capture", int, description="Only this capture's")])
    def get(self, request, pk):
        project = assigning_project(request, pk)
        rows = (Assignment.objects.filter(capture__project=project)
                .select_related("capture", "annotator", "assigned_by").prefetch_related("capture__reviews"))
        capture = int_param(request, "capture", None)
        if capture is not None:
            rows = rows.filter(capture_id=capture)
        return Response(AssignmentSerializer(rows, many=True).data)

    @extend_schema(request=AssignRequest, responses={201: AssignmentSerializer(many=True)})
    def post(self, request, pk):
        project = assigning_project(request, pk)
        data = body(request, AssignRequest)
        made = service.do_assign(project, request.user, data["captures"], data["annotators"],
                                 data["per_capture"])
        return Response(AssignmentSerializer(made, many=True).data, status=201)


class AssignmentView(APIView):
    def assignment(self, request, pk, assignment_id):
        project = assigning_project(request, pk)
        return get_object_or_404(Assignment.objects.filter(capture__project=project), pk=assignment_id)

    @extend_schema(request=ReassignRequest, responses=AssignmentSerializer)
    def patch(self, request, pk, assignment_id):
        """Reassign: give the capture to another member instead."""
        assignment = self.assignment(request, pk, assignment_id)
        data = body(request, ReassignRequest)
        return Response(AssignmentSerializer(service.do_reassign(assignment, request.user, data["annotator"])).data)

    @extend_schema(request=None, responses={204: None})
    def delete(self, request, pk, assignment_id):
        """Unassign (the annotator's review, if any, is kept)."""
        service.do_unassign(self.assignment(request, pk, assignment_id))
        return Response(status=204)


class QueueView(APIView):
    @extend_schema(
        responses=QueueItemSerializer(many=True),
        parameters=[
            OpenApiParameter("project", int, description="Only this project's captures"),
            OpenApiParameter("user", str, description="Another member's queue (reviewers and admins "
                                                       "of the project given in `project` only)"),
        ],
    )
    def get(self, request):
        """The caller's queue (or, for a reviewer, a member's): assigned, in progress,
        returned and submitted captures, oldest first."""
        project_id = int_param(request, "project", None)
        project = project_for(request.user, project_id) if project_id is not None else None
        user = request.user
        username = request.query_params.get("user")
        if username and username != user.username:
            if project is None or not project.can_see_all_reviews(user):
                raise PermissionDenied("Only a project's reviewers and admins see another member's "
                                       "queue, and only with ?project=.")
            user = get_object_or_404(get_user_model(), username=username, memberships__project=project)
        items = queues.queue(user, project)
        if project is None:
            visible = set(Project.objects.for_user(request.user).values_list("id", flat=True))
            items = [i for i in items if i["capture"]["project"] in visible]
        return Response(QueueItemSerializer(items, many=True).data)


class ReturnView(APIView):
    @extend_schema(request=ReturnRequest, responses=ReviewSerializer)
    def post(self, request, pk, review_id):
        """Return a submitted review to its annotator with a comment (reviewers, admins)."""
        capture = capture_for(request.user, pk)
        if not capture.project.can_see_all_reviews(request.user):
            raise PermissionDenied("Only the project's reviewers and admins return reviews.")
        review = get_object_or_404(capture.reviews, pk=review_id)
        data = body(request, ReturnRequest)
        review = returns.do_return_review(review, request.user, data["comment"])
        return Response(ReviewSerializer(review).data)


urlpatterns = [
    path("projects/<int:pk>/assignments/", AssignmentsView.as_view(), name="api-assignments"),
    path("projects/<int:pk>/assignments/<int:assignment_id>/", AssignmentView.as_view(),
         name="api-assignment"),
    path("queue/", QueueView.as_view(), name="api-queue"),
    path("captures/<int:pk>/reviews/<int:review_id>/return/", ReturnView.as_view(), name="api-review-return"),
]
