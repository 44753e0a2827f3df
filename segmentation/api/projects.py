"""Projects, members, labels, the caller, and the method catalogue."""

from django.shortcuts import get_object_or_404
from drf_spectacular.utils import extend_schema
from rest_framework import mixins, viewsets
from rest_framework.decorators import action
from rest_framework.exceptions import PermissionDenied
from rest_framework.response import Response
from rest_framework.views import APIView

from motionlib.segmenters import list_segmenters
from segmentation import services, storage
from segmentation.api.invitations import InvitationSerializer, InvitedSerializer, invited_response
from segmentation.api.params import body
from segmentation.api.serializers import (
    CutModelSerializer,
    LabelSerializer,
    MemberSerializer,
    MeSerializer,
    MethodSerializer,
    ProjectSerializer,
)
from segmentation.models import Membership, Project
from segmentation.services.invitations import can_see_accounts
from segmentation.services.team import can_create_accounts


class ProjectViewSet(
    mixins.ListModelMixin,
    mixins.RetrieveModelMixin,
    mixins.CreateModelMixin,
    mixins.UpdateModelMixin,
    viewsets.GenericViewSet,
):
    serializer_class = ProjectSerializer
    http_method_names = ["get", "post", "patch", "delete", "head", "options"]

    def get_queryset(self):
        return Project.objects.for_user(self.request.user).prefetch_related("labels").order_by("id")

    def perform_create(self, serializer):
        serializer.instance = services.do_create_project(self.request.user, **serializer.validated_data)

    def perform_update(self, serializer):
        project = self._admin_project()
        serializer.instance = services.do_update_project(project, **serializer.validated_data)

    def _admin_project(self):
        project = self.get_object()
        if self.request.method != "GET" and not project.can_manage(self.request.user):
            raise PermissionDenied("Only the project's admins can change it, its labels and members.")
        return project

    @extend_schema(methods=["GET"], responses=LabelSerializer(many=True))
    @extend_schema(methods=["POST"], request=LabelSerializer, responses={201: LabelSerializer})
    @action(detail=True, methods=["get", "post"], serializer_class=LabelSerializer)
    def labels(self, request, pk=None):
        project = self._admin_project()
        if request.method == "GET":
            return Response(LabelSerializer(project.labels.all(), many=True).data)
        label = services.do_add_label(project, **body(request, LabelSerializer))
        return Response(LabelSerializer(label).data, status=201)

    @extend_schema(methods=["GET"], responses=MemberSerializer(many=True))
    @extend_schema(methods=["POST"], request=MemberSerializer,
                   responses={200: MemberSerializer, 202: InvitedSerializer})
    @action(detail=True, methods=["get", "post"], serializer_class=MemberSerializer)
    def members(self, request, pk=None):
        project = self._admin_project()
        if request.method == "GET":
            if not project.can_see_all_reviews(request.user):
                raise PermissionDenied("Only the project's reviewers and admins see its members.")
            members = project.memberships.select_related("user").order_by("id")
            return Response(MemberSerializer(members, many=True).data)
        data = body(request, MemberSerializer)
        added = services.do_add_member(project, request.user, data["user"]["username"], data["role"])
        if isinstance(added, Membership):
            return Response(MemberSerializer(added).data)
        # Anyone not yet a member is invited; the answer is the same whether or not an
        # account has that name, so a project cannot be used to find out.
        return invited_response(added)

    @extend_schema(responses=InvitationSerializer(many=True))
    @action(detail=True, methods=["get"])
    def invitations(self, request, pk=None):
        """Pending invitations (expired and answered ones are left out)."""
        project = self._admin_project()
        if not project.can_manage(request.user):
            raise PermissionDenied("Only the project's admins see its invitations.")
        invitations = project.invitations.pending().select_related("invited_by")
        return Response(InvitationSerializer(invitations, many=True).data)

    @extend_schema(request=None, responses={204: None})
    @action(detail=True, methods=["delete"], url_path=r"invitations/(?P<invitation_id>\d+)")
    def cancel_invitation(self, request, pk=None, invitation_id=None):
        project = self._admin_project()
        invitation = get_object_or_404(project.invitations.pending(), pk=invitation_id)
        services.do_cancel_invitation(invitation, request.user)
        return Response(status=204)


    @extend_schema(responses=CutModelSerializer(many=True))
    @action(detail=True, url_path="cut-models")
    def cut_models(self, request, pk=None):
        """The project's trainings, newest first: versions learnt from its reviews, and
        failed trainings with their reason (detection keeps the newest version)."""
        return Response(CutModelSerializer(self.get_object().cut_models.all()[:50], many=True).data)


class MeView(APIView):
    @extend_schema(responses=MeSerializer)
    def get(self, request):
        projects = [
            {"id": m.project_id, "name": m.project.name, "role": m.role}
            for m in request.user.memberships.select_related("project").order_by("project_id")
        ]
        # What the service admits, so the pages refuse the same (e.g. a skeleton too big to draw).
        limits = {"max_joints": storage.input_limits().max_joints}
        return Response(MeSerializer({
            "id": request.user.pk, "username": request.user.username, "projects": projects,
            "limits": limits, "can_create_accounts": can_create_accounts(request.user),
            "can_see_accounts": can_see_accounts(request.user)}).data)


class MethodsView(APIView):
    @extend_schema(responses=MethodSerializer(many=True))
    def get(self, request):
        return Response(MethodSerializer([cls.schema() for cls in list_segmenters()], many=True).data)


def project_for(user, pk):
    """A project the user is a member of, or 404 (never 403, which would leak it)."""
    return get_object_or_404(Project.objects.for_user(user), pk=pk)
