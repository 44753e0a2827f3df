"""Team management and the label taxonomy, for a project's admins: change a member's
role, remove a member, create an account (site admins only), edit, reorder and merge
labels.

Adding an existing user is ``POST /api/projects/{id}/members/`` (an invitation, see
``segmentation.api.invitations``).
"""

from django.shortcuts import get_object_or_404
from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework import serializers
from rest_framework.exceptions import PermissionDenied
from rest_framework.response import Response
from rest_framework.views import APIView

from segmentation.api.common.params import body
from segmentation.api.common.serializers.base import Text
from segmentation.api.common.serializers.projects import LabelSerializer, MemberSerializer
from segmentation.errors import Invalid
from segmentation.limits import USERNAME_LENGTH, text_limit
from segmentation.models import ROLES, Label
from segmentation.queries.access import project_for
from segmentation.services import taxonomy, team


def admin_project(request, pk):
    project = project_for(request.user, pk)
    if not project.can_manage(request.user):
        raise PermissionDenied("Only the project's admins change its members and labels.")
    return project


class RoleRequest(serializers.Serializer):
    role = serializers.ChoiceField(choices=ROLES)


class NewAccountRequest(serializers.Serializer):
    username = Text(USERNAME_LENGTH)
    role = serializers.ChoiceField(choices=ROLES)


class NewAccountResponse(MemberSerializer):
    password = serializers.CharField(help_text="The one-time password; shown only in this answer.")


class LabelChange(serializers.Serializer):
    name = Text(text_limit(Label, "name"), required=False)
    color = Text(text_limit(Label, "color"), required=False)
    hotkey = Text(text_limit(Label, "hotkey"), required=False, allow_null=True, allow_blank=True)
    retired = serializers.BooleanField(required=False)


class LabelMerge(serializers.Serializer):
    into = serializers.IntegerField(help_text="The id of the project's label that takes its place.")


class LabelOrder(serializers.Serializer):
    order = serializers.ListField(child=serializers.IntegerField())


class MemberView(APIView):
    def membership(self, request, pk, user_id):
        project = admin_project(request, pk)
        return project, get_object_or_404(project.memberships.select_related("user"), user_id=user_id)

    @extend_schema(request=RoleRequest, responses=MemberSerializer)
    def patch(self, request, pk, user_id):
        """Change a member's role (the last admin cannot be demoted)."""
        project, membership = self.membership(request, pk, user_id)
        data = body(request, RoleRequest)
        return Response(MemberSerializer(team.do_change_role(project, membership, data["role"])).data)

    @extend_schema(request=None, responses={204: None})
    def delete(self, request, pk, user_id):
        """Remove a member (not the last admin); their reviews stay."""
        project, membership = self.membership(request, pk, user_id)
        team.do_remove_member(project, membership)
        return Response(status=204)


class NewAccountView(APIView):
    @extend_schema(request=NewAccountRequest, responses={201: NewAccountResponse})
    def post(self, request, pk):
        """Create an account with a one-time password and add it to the project.

        Site admins only (project admins invite existing users instead), so that nobody
        can use it to find out which usernames exist."""
        project = admin_project(request, pk)
        data = body(request, NewAccountRequest)
        membership, password = team.do_create_account(project, request.user, data["username"], data["role"])
        return Response({**MemberSerializer(membership).data, "password": password}, status=201)


class LabelView(APIView):
    @extend_schema(request=LabelChange, responses=LabelSerializer)
    def patch(self, request, pk, label_id):
        """Rename, recolour, set or clear the hotkey, retire or restore a label."""
        project = admin_project(request, pk)
        label = get_object_or_404(project.labels, pk=label_id)
        data = body(request, LabelChange)
        return Response(LabelSerializer(taxonomy.do_change_label(label, **data)).data)


class LabelMergeView(APIView):
    @extend_schema(request=LabelMerge, responses=LabelSerializer)
    def post(self, request, pk, label_id):
        """Merge a label into another of the project's: every segment, gold version and
        proposal that carries it carries the other instead, and it is deleted."""
        project = admin_project(request, pk)
        label = get_object_or_404(project.labels, pk=label_id)
        data = body(request, LabelMerge)
        into = project.labels.filter(pk=data["into"]).first()
        if into is None:
            raise Invalid(f"into: the project has no label {data['into']}")
        return Response(LabelSerializer(taxonomy.do_merge_labels(label, into)).data)


class LabelOrderView(APIView):
    @extend_schema(request=LabelOrder, responses=LabelSerializer(many=True))
    def post(self, request, pk):
        project = admin_project(request, pk)
        data = body(request, LabelOrder)
        return Response(LabelSerializer(taxonomy.do_reorder_labels(project, data["order"]), many=True).data)


urlpatterns = [
    path("projects/<int:pk>/members/<int:user_id>/", MemberView.as_view(), name="api-member"),
    path("projects/<int:pk>/members/new-account/", NewAccountView.as_view(), name="api-member-new-account"),
    path("projects/<int:pk>/labels/<int:label_id>/", LabelView.as_view(), name="api-label"),
    path("projects/<int:pk>/labels/<int:label_id>/merge/", LabelMergeView.as_view(), name="api-label-merge"),
    path("projects/<int:pk>/labels/order/", LabelOrderView.as_view(), name="api-label-order"),
]
