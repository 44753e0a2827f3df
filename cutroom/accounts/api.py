"""API tokens: obtain one (throttled like the login page), list and revoke your own.
Passwords: change your own, or (site admins) reset someone's."""

from django.contrib.auth import get_user_model, update_session_auth_hash
from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework import serializers, status
from rest_framework.authtoken.serializers import AuthTokenSerializer
from rest_framework.exceptions import PermissionDenied, Throttled, ValidationError
from rest_framework.generics import get_object_or_404
from rest_framework.permissions import AllowAny
from rest_framework.response import Response
from rest_framework.views import APIView

from cutroom.accounts import passwords, throttle
from cutroom.accounts.models import ApiToken


class ApiTokenSerializer(serializers.ModelSerializer):
    current = serializers.SerializerMethodField()

    class Meta:
        model = ApiToken
        fields = ["id", "prefix", "created_at", "expires_at", "last_used_at", "current"]

    def get_current(self, token) -> bool:
        return token == self.context["request"].auth


class IssuedTokenSerializer(serializers.Serializer):
    token = serializers.CharField(help_text="The key; shown only in this answer.")
    expires_at = serializers.DateTimeField()


class RevokedSerializer(serializers.Serializer):
    revoked = serializers.IntegerField(help_text="How many tokens were revoked")


class TokenView(APIView):
    """POST: a new token for a username and password. DELETE: revoke the token this
    request was made with."""

    def obtaining(self):
        return getattr(self.request, "method", None) == "POST"

    def get_authenticators(self):
        # Obtaining a token needs no credentials but the password; a stale token sent
        # along out of habit must not get in the way.
        return [] if self.obtaining() else super().get_authenticators()

    def get_permissions(self):
        return [AllowAny()] if self.obtaining() else super().get_permissions()

    @extend_schema(request=AuthTokenSerializer, responses=IssuedTokenSerializer)
    def post(self, request):
        wait = throttle.admit(request, throttle.username_of(request.data))
        if wait:
            raise Throttled(wait, "Too many failed sign-ins for this account or from this address.")
        serializer = AuthTokenSerializer(data=request.data, context={"request": request})
        serializer.is_valid(raise_exception=True)
        user = serializer.validated_data["user"]
        throttle.succeeded(request, user.get_username())
        if passwords.is_one_time(user):
            raise PermissionDenied("This account still has its one-time password: sign in at "
                                   "/login/ and choose your own first, then ask for a token.")
        token, key = ApiToken.objects.issue(user)
        return Response(IssuedTokenSerializer({"token": key, "expires_at": token.expires_at}).data)

    @extend_schema(responses={204: None})
    def delete(self, request):
        if not isinstance(request.auth, ApiToken):
            detail = ("This request carries no token (it is signed in by session); "
                      "DELETE /api/auth/tokens/ revokes all of yours.")
            return Response({"detail": detail}, status=status.HTTP_400_BAD_REQUEST)
        request.auth.delete()
        return Response(status=status.HTTP_204_NO_CONTENT)


class TokensView(APIView):
    """The caller's live tokens (never their keys); DELETE revokes them all."""

    @extend_schema(responses=ApiTokenSerializer(many=True))
    def get(self, request):
        tokens = request.user.api_tokens.live().order_by("-created_at", "-id")
        return Response(ApiTokenSerializer(tokens, many=True, context={"request": request}).data)

    @extend_schema(operation_id="auth_tokens_revoke_all", responses=RevokedSerializer)
    def delete(self, request):
        revoked, _ = request.user.api_tokens.all().delete()
        return Response(RevokedSerializer({"revoked": revoked}).data)


class OneTokenView(APIView):
    @extend_schema(operation_id="auth_tokens_revoke", responses={204: None})
    def delete(self, request, pk):
        get_object_or_404(request.user.api_tokens.all(), pk=pk).delete()
        return Response(status=status.HTTP_204_NO_CONTENT)


# A password longer than this is refused before it is hashed (hashing costs time per byte).
PASSWORD_MAX = 4096


class PasswordChangeSerializer(serializers.Serializer):
    current_password = serializers.CharField(trim_whitespace=False, max_length=PASSWORD_MAX)
    new_password = serializers.CharField(trim_whitespace=False, max_length=PASSWORD_MAX)


class PasswordChangedSerializer(serializers.Serializer):
    detail = serializers.CharField()


class PasswordResetSerializer(serializers.Serializer):
    username = serializers.CharField()
    password = serializers.CharField(help_text="The one-time password; shown only in this answer.")


def refuse(exc):
    """A PasswordError as a 400 whose detail names the field."""
    return ValidationError({"detail": str(exc), exc.field: [str(exc).split(": ", 1)[1]]})


class PasswordView(APIView):
    """POST changes the caller's password: their other sessions and all their API tokens
    (this request's too) stop working; a session making the change stays signed in."""

    @extend_schema(request=PasswordChangeSerializer, responses=PasswordChangedSerializer)
    def post(self, request):
        serializer = PasswordChangeSerializer(data=request.data)
        serializer.is_valid(raise_exception=True)
        user = request.user
        # Checking the current password is a sign-in attempt: same throttle, same count.
        wait = throttle.admit(request, user.get_username())
        if wait:
            raise Throttled(wait, "Too many failed sign-ins for this account or from this address.")
        data = serializer.validated_data
        try:
            passwords.change(user, data["current_password"], data["new_password"])
        except passwords.PasswordError as exc:
            if exc.field == "new_password":
                throttle.succeeded(request, user.get_username())  # the current one was right
            raise refuse(exc) from None
        throttle.succeeded(request, user.get_username())
        if not isinstance(request.auth, ApiToken):
            update_session_auth_hash(request, user)
        detail = "Password changed. Your other sessions and your API tokens are signed out."
        return Response(PasswordChangedSerializer({"detail": detail}).data)


class PasswordResetView(APIView):
    """POST (site admins) gives an account a new one-time password, ending its sessions
    and revoking its API tokens."""

    @extend_schema(request=None, responses=PasswordResetSerializer)
    def post(self, request, pk):
        if not passwords.can_reset(request.user):
            raise PermissionDenied("Only site admins reset other people's passwords.")
        user = get_object_or_404(get_user_model().objects.all(), pk=pk)
        password = passwords.reset(user)
        if user == request.user and not isinstance(request.auth, ApiToken):
            update_session_auth_hash(request, user)
        return Response(PasswordResetSerializer({"username": user.get_username(),
                                                 "password": password}).data)


urlpatterns = [
    path("auth/password/", PasswordView.as_view(), name="api-password"),
    path("auth/users/<int:pk>/password-reset/", PasswordResetView.as_view(),
         name="api-password-reset"),
    path("auth/token/", TokenView.as_view(), name="api-token"),
    path("auth/tokens/", TokensView.as_view(), name="api-tokens"),
    path("auth/tokens/<int:pk>/", OneTokenView.as_view(), name="api-token-revoke"),
]
