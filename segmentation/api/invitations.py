"""Invitations: the invitee's list, accept and decline; the project admin's pending list."""

from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import extend_schema, extend_schema_field
from rest_framework import serializers
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation import services
from segmentation.api.common.serializers.base import DetailSerializer, NamedRefSerializer
from segmentation.api.common.serializers.projects import MemberSerializer
from segmentation.models import Invitation


class MyInvitationSerializer(serializers.ModelSerializer):
    """An invitation as the invitee sees it: which project, what role, from whom."""

    project = serializers.SerializerMethodField()
    invited_by = serializers.CharField(source="invited_by.username", default=None)

    class Meta:
        model = Invitation
        fields = ["id", "project", "role", "invited_by", "created_at", "expires_at"]

    @extend_schema_field(NamedRefSerializer)
    def get_project(self, invitation):
        return {"id": invitation.project_id, "name": invitation.project.name}


class AcceptedSerializer(MemberSerializer):
    """The caller's new membership, and its project."""

    project = NamedRefSerializer()


class MyInvitationsView(APIView):
    @extend_schema(responses=MyInvitationSerializer(many=True))
    def get(self, request):
        invitations = Invitation.objects.for_user(request.user).select_related("project", "invited_by")
        return Response(MyInvitationSerializer(invitations, many=True).data)


class AnswerView(APIView):
    """POST answers one of the caller's invitations; anybody else's is a 404."""

    def invitation(self, request, pk):
        return get_object_or_404(Invitation.objects.for_user(request.user), pk=pk)


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
