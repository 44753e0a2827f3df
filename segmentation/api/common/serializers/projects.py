"""JSON shapes of projects (docs/api.md): projects, labels, members, invitations, the
caller, methods."""

from drf_spectacular.utils import extend_schema_field
from rest_framework import serializers

from segmentation.api.common.serializers.base import DetailSerializer, Text
from segmentation.limits import USERNAME_LENGTH, text_limit
from segmentation.models import ROLES, Invitation, Label, Project


class LabelSerializer(serializers.ModelSerializer):
    name = Text(text_limit(Label, "name"))
    hotkey = Text(text_limit(Label, "hotkey"), allow_null=True, required=False, default=None)
    color = Text(text_limit(Label, "color"), required=False, default="#888888")

    class Meta:
        model = Label
        fields = ["id", "name", "color", "hotkey", "position", "retired"]
        read_only_fields = ["position", "retired"]
        # Uniqueness is checked by the service with a message naming the clash.
        validators = []


class ProjectSerializer(serializers.Serializer):
    id = serializers.IntegerField(read_only=True)
    name = Text(text_limit(Project, "name"))
    role = serializers.SerializerMethodField()
    default_method = Text(text_limit(Project, "default_method"), required=False, allow_blank=True,
                          default="")
    default_params = serializers.DictField(required=False, default=dict)
    annotators_pick_unassigned = serializers.BooleanField(required=False, default=True)
    labels = LabelSerializer(many=True, read_only=True)

    # Never null: projects are listed to, and created by, their members only.
    @extend_schema_field(serializers.ChoiceField(choices=ROLES))
    def get_role(self, project):
        return project.role_of(self.context["request"].user)


class MyProjectSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    name = serializers.CharField()
    role = serializers.ChoiceField(choices=ROLES)


class LimitsSerializer(serializers.Serializer):
    """What the service admits, so the pages refuse the same."""

    max_joints = serializers.IntegerField()


class MeSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    username = serializers.CharField()
    projects = MyProjectSerializer(many=True)
    limits = LimitsSerializer()
    can_create_accounts = serializers.BooleanField()
    can_see_accounts = serializers.BooleanField(
        help_text="A site admin who may see accounts: inviting a name no account has is refused, "
        "saying so (to anyone else the answer is the same whether or not the name exists).")


class ParamSerializer(serializers.Serializer):
    """One parameter of a segmentation method."""

    type = serializers.CharField()
    default = serializers.JSONField(allow_null=True)
    min = serializers.FloatField(allow_null=True)
    max = serializers.FloatField(allow_null=True)
    description = serializers.CharField()


class MethodSerializer(serializers.Serializer):
    """A segmentation method of the catalogue and its parameters."""

    name = serializers.CharField()
    title = serializers.CharField()
    description = serializers.CharField()
    params = serializers.DictField(child=ParamSerializer())


class MemberSerializer(serializers.Serializer):
    id = serializers.IntegerField(source="user.id", read_only=True)
    username = Text(USERNAME_LENGTH, source="user.username", error_messages={
        "max_length": "must be 1 to {max_length} characters, got %(show_value)d"})
    role = serializers.ChoiceField(choices=ROLES)


# What a project admin is told, whether or not an account has the username.
INVITED = ("If an account is named {username!r}, it is invited as {role} and joins the "
           "project once it accepts.")


class InvitationSerializer(serializers.ModelSerializer):
    """An invitation as the project's admins see it (the invitee's username as typed)."""

    invited_by = serializers.CharField(source="invited_by.username", default=None)

    class Meta:
        model = Invitation
        fields = ["id", "username", "role", "invited_by", "created_at", "expires_at"]


class InvitedSerializer(DetailSerializer):
    """What a project admin is told on adding a member who is not one yet."""

    invitation = InvitationSerializer()
