from drf_spectacular.authentication import SessionScheme
from rest_framework.authentication import SessionAuthentication, TokenAuthentication
from rest_framework.exceptions import AuthenticationFailed
from rest_framework.request import is_form_media_type

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


class CsrfFirstSessionAuthentication(SessionAuthentication):
    """DRF's session sign-in, whose CSRF check never parses the body first.

    Django's CSRF check looks for ``csrfmiddlewaretoken`` in ``request.POST``; handed
    DRF's request, that parses the body with the API's parsers, so a cross-site
    ``text/plain`` post (which a plain HTML form can send) was answered 415 before the
    check could refuse it. Django's own request reads ``POST`` only from form bodies and
    leaves any other body unread, so the check refuses first with its 403.
    """

    def enforce_csrf(self, request):
        if not is_form_media_type(request.content_type):
            request = request._request
        super().enforce_csrf(request)


class CsrfFirstSessionScheme(SessionScheme):
    """The API schema's cookie sign-in, for ``CsrfFirstSessionAuthentication``."""

    target_class = CsrfFirstSessionAuthentication
