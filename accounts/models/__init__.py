"""The accounts' records: API tokens and the record of failed sign-ins (here), the key of
each account's username (``usernames``) and the named row locks that count attempts
against a limit (``locks``).

Both live in the database because every web process must see the same state: a token
revoked through one process is refused by all, and failures counted by one process
throttle the next attempt whichever process receives it.
"""

import hashlib
import secrets
from datetime import timedelta

from django.conf import settings
from django.db import models
from django.utils import timezone

from accounts.models.locks import ThrottleLock
from accounts.models.passwords import OneTimePassword
from accounts.models.usernames import UsernameKey

__all__ = ["ApiToken", "LoginFailure", "OneTimePassword", "ThrottleLock", "UsernameKey", "digest"]

# A script that asks for a token on every run must not grow the table without bound.
MAX_TOKENS_PER_USER = 20
# last_used_at is informative only; writing it on every request would cost a write each.
TOUCH_EVERY = timedelta(minutes=1)


def digest(text):
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


class ApiTokenQuerySet(models.QuerySet):
    def live(self):
        return self.filter(expires_at__gt=timezone.now())

    def for_key(self, key):
        """The token whose key is ``key`` (expired or not), or None."""
        return self.select_related("user").filter(digest=digest(key)).first()

    def issue(self, user):
        """A new token for ``user`` and its key; the key is shown once and never stored.

        Expired tokens of the user are dropped, and beyond ``MAX_TOKENS_PER_USER`` live
        ones the oldest are revoked.
        """
        now = timezone.now()
        self.filter(user=user, expires_at__lte=now).delete()
        key = secrets.token_hex(20)
        token = self.create(
            user=user, digest=digest(key), prefix=key[:6], created_at=now,
            expires_at=now + timedelta(days=settings.CUTROOM_TOKEN_DAYS),
        )
        keep = self.filter(user=user).order_by("-created_at", "-id")[:MAX_TOKENS_PER_USER]
        self.filter(user=user).exclude(pk__in=list(keep.values_list("pk", flat=True))).delete()
        return token, key


class ApiToken(models.Model):
    """A key a script sends as ``Authorization: Token <key>``.

    Only the key's SHA-256 digest is stored, so a copy of the database holds no usable
    key. A token works until ``expires_at`` (``CUTROOM_TOKEN_DAYS`` after it was issued);
    revoking it deletes the row.
    """

    user = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="api_tokens")
    digest = models.CharField(max_length=64, unique=True)
    # The key's first characters, so a person can tell their tokens apart in a list.
    prefix = models.CharField(max_length=6)
    created_at = models.DateTimeField(default=timezone.now)
    expires_at = models.DateTimeField()
    last_used_at = models.DateTimeField(null=True, blank=True)

    objects = ApiTokenQuerySet.as_manager()

    class Meta:
        verbose_name = "API token"

    def __str__(self):
        return f"{self.prefix}… of {self.user}"

    def is_expired(self):
        return self.expires_at <= timezone.now()

    def touch(self):
        now = timezone.now()
        if self.last_used_at is None or now - self.last_used_at > TOUCH_EVERY:
            ApiToken.objects.filter(pk=self.pk).update(last_used_at=now)
            self.last_used_at = now


class LoginFailure(models.Model):
    """One failed sign-in, counted against one key: the username tried or the address.

    The key is a digest of ``user:<name>`` or ``addr:<address>``, so what people typed
    into the username field (sometimes a password) is not kept. Rows older than the
    throttling window are deleted as new failures come in.
    """

    key = models.CharField(max_length=64)
    at = models.DateTimeField(default=timezone.now)

    class Meta:
        indexes = [
            models.Index(fields=["key", "at"], name="login_failure_key_at"),
            models.Index(fields=["at"], name="login_failure_at"),
        ]

    def __str__(self):
        return f"{self.key[:8]}… at {self.at:%Y-%m-%d %H:%M:%S}"
