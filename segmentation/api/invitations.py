"""Invitations: the invitee's list, accept and decline; the project admin's pending list."""

from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework import serializers
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.serializers import MemberSerializer
from segmentation.models import Invitation

# What a project admin is told, whether or not an account has the username.
INVITED = ("If an account is named {username!r}, it is invited as {role} and joins the "
           "project once it accepts.")


class InvitationSerializer(serializers.ModelSerializer):
    """An invitation as the project's admins see it (the invitee's username as typed)."""

    invited_by = serializers.CharField(source="invited_by.username", default=None)

    class Meta:
        model = Invitation
        fields = ["id", "username", "role", "invited_by", "created_at", "expires_at"]


class MyInvitationSerializer(serializers.ModelSerializer):
    """An invitation as the invitee sees it: which project, what role, from whom."""

    project = serializers.SerializerMethodField()
    invited_by = serializers.CharField(source="invited_by.username", default=None)

    class Meta:
        model = Invitation
        fields = ["id", "project", "role", "invited_by", "created_at", "expires_at"]

    def get_project(self, invitation) -> dict:
        return {"id": invitation.project_id, "name": invitation.project.name}


def invited_response(invitation):
    body = {
        "detail": INVITED.format(username=invitation.username, role=invitation.role),
        "invitation": InvitationSerializer(invitation).data,
    }
    return Response(body, status=202)


class MyInvitationsView(APIView):
    @extend_schema(responses=MyInvitationSerializer(many=True))
    def get(self, request):
        invitations = Invitation.objects.for_user(request.user).select_related("project", "invited_by")
        return Response(MyInvitationSerializer(invitations, many=True).data)


class AnswerView(APIView):
    """POST accepts (``accept``) or declines (``decline``) one of the caller's invitations;
    anybody else's is a 404."""

    accept = True

    @extend_schema(request=None, responses=dict)
    def post(self, request, pk):
        invitation = get_object_or_404(Invitation.objects.for_user(request.user), pk=pk)
        if not self.accept:
            services.do_decline_invitation(invitation, request.user)
            return Response({"detail": f"Declined joining {invitation.project.name!r}."})
        membership = services.do_accept_invitation(invitation, request.user)
        project = {"id": invitation.project_id, "name": invitation.project.name}
        return Response({"project": project, **MemberSerializer(membership).data})


urlpatterns = [
    path("invitations/", MyInvitationsView.as_view(), name="api-invitations"),
    path("invitations/<int:pk>/accept/", AnswerView.as_view(accept=True), name="api-invitation-accept"),
    path("invitations/<int:pk>/decline/", AnswerView.as_view(accept=False), name="api-invitation-decline"),
]
