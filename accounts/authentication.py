from rest_framework.authentication import TokenAuthentication
from rest_framework.exceptions import AuthenticationFailed

from accounts.models import ApiToken


class ExpiringTokenAuthentication(TokenAuthentication):
    """``Authorization: Token <key>`` with an ``ApiToken``: refused once expired or revoked.

    Listed first among the API's authentication classes, so an anonymous call is answered
    401 with ``WWW-Authenticate: Token`` (DRF takes the header from the first class).
    """

    def authenticate_credentials(self, key):
        token = ApiToken.objects.for_key(key)
        if token is None:
            raise AuthenticationFailed("Invalid token (revoked, or never issued).")
        if token.is_expired():
            raise AuthenticationFailed(
                f"Token expired at {token.expires_at:%Y-%m-%d %H:%M} UTC; "
                "POST /api/auth/token/ for a new one."
            )
        if not token.user.is_active:
            raise AuthenticationFailed("User inactive or deleted.")
        token.touch()
        return token.user, token
