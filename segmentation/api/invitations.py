"""Invitations: the invitee's list, accept and decline; the project admin's pending list."""

from django.http import Http404
from django.urls import path
from django.utils import timezone
from drf_spectacular.utils import extend_schema, extend_schema_field
from rest_framework import serializers
from rest_framework.exceptions import APIException
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.common.serializers.base import DetailSerializer, NamedRefSerializer
from segmentation.api.common.serializers.projects import MemberSerializer
from segmentation.limits import shown_name
from segmentation.models import Invitation


class MyInvitationSerializer(serializers.ModelSerializer):
    """An invitation as the invitee sees it: which project, what role, from whom; the
    project's name on one line, without invisible characters, cut short: it names the
    project and carries no message."""

    project = serializers.SerializerMethodField()
    invited_by = serializers.CharField(source="invited_by.username", default=None)

    class Meta:
        model = Invitation
        fields = ["id", "project", "role", "invited_by", "created_at", "expires_at"]

    @extend_schema_field(NamedRefSerializer)
    def get_project(self, invitation):
        return {"id": invitation.project_id, "name": shown_name(invitation.project.name)}


class AcceptedSerializer(MemberSerializer):
    """The caller's new membership, and its project."""

    project = NamedRefSerializer()


class MyInvitationsView(APIView):
    @extend_schema(responses=MyInvitationSerializer(many=True))
    def get(self, request):
        invitations = Invitation.objects.for_user(request.user).select_related("project", "invited_by")
        return Response(MyInvitationSerializer(invitations, many=True).data)


class Gone(APIException):
    status_code = 410
    default_detail = "This invitation can no longer be answered."


class AnswerView(APIView):
    """POST answers one of the caller's invitations; anybody else's is a 404."""

    def invitation(self, request, pk):
        """The caller's pending invitation ``pk``; one of theirs that was cancelled, has
        expired or was answered already is a 410 saying which (not a bare refusal)."""
        invitation = (Invitation.objects.filter(pk=pk, username=request.user.get_username())
                      .select_related("project").first())
        if invitation is None:
            raise Http404("No Invitation matches the given query.")
        project = invitation.project.name
        if invitation.status == "cancelled":
            raise Gone(f"This invitation to {project!r} was cancelled by the project's admins.")
        if invitation.status != "pending":
            raise Gone(f"This invitation to {project!r} was {invitation.status} already.")
        if invitation.expires_at <= timezone.now():
            raise Gone(f"This invitation to {project!r} has expired "
                       f"({invitation.expires_at:%Y-%m-%d %H:%M} UTC); ask one of the "
                       "project's admins to invite you again.")
        return invitation


class AcceptView(AnswerView):
    @extend_schema(request=None, responses=AcceptedSerializer)
    def post(self, request, pk):
        membership = services.do_accept_invitation(self.invitation(request, pk), request.user)
        return Response(AcceptedSerializer(membership).data)


class DeclineView(AnswerView):
    @extend_schema(request=None, responses=DetailSerializer)
    def post(self, request, pk):
        invitation = self.invitation(request, pk)
        services.do_decline_invitation(invitation, request.user)
        return Response(DetailSerializer({"detail": f"Declined joining {invitation.project.name!r}."}).data)


urlpatterns = [
    path("invitations/", MyInvitationsView.as_view(), name="api-invitations"),
    path("invitations/<int:pk>/accept/", AcceptView.as_view(), name="api-invitation-accept"),
    path("invitations/<int:pk>/decline/", DeclineView.as_view(), name="api-invitation-decline"),
]
