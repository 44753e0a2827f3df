"""API tokens: obtain one (throttled like the login page), list and revoke your own."""

from django.urls import path
from drf_spectacular.utils import extend_schema
from rest_framework import serializers, status
from rest_framework.authtoken.serializers import AuthTokenSerializer
from rest_framework.exceptions import Throttled
from rest_framework.generics import get_object_or_404
from rest_framework.permissions import AllowAny
from rest_framework.response import Response
from rest_framework.views import APIView

from cutroom.accounts import throttle
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


urlpatterns = [
    path("auth/token/", TokenView.as_view(), name="api-token"),
    path("auth/tokens/", TokensView.as_view(), name="api-tokens"),
    path("auth/tokens/<int:pk>/", OneTokenView.as_view(), name="api-token-revoke"),
]
