"""The key of each account's username (``segmentation.usernames``), stored and unique; and
which accounts still sign in with a one-time password."""

from django.conf import settings
from django.db import models
from django.utils import timezone


class UsernameKey(models.Model):
    """One row per account: a digest of ``usernames.key(username)``.

    Sign-in finds an account by any spelling of its name with one indexed lookup, on
    every database: SQLite's case-insensitive match knows only ASCII, so a Greek or
    Cyrillic name typed in another case would find nothing. The unique index also makes
    two accounts whose names differ only in case or form impossible, even when both are
    created at the same moment. A digest, not the key itself: NFKC and case folding can
    make a 150-character name many times longer, past what an index holds.

    ``digest`` is empty for an account whose name shares its key with an older account's
    (names made before the rules, or renamed into a clash): that account signs in by its
    exact stored name only, and ``manage.py check_usernames`` lists it.
    """

    user = models.OneToOneField(settings.AUTH_USER_MODEL, on_delete=models.CASCADE,
                                primary_key=True, related_name="username_key")
    # NULL, not "": many accounts may have no key, and unique counts NULLs as distinct.
    digest = models.CharField(max_length=64, unique=True, null=True)  # noqa: DJ001

    def __str__(self):
        return f"{self.user_id}: {(self.digest or '-')[:8]}…"


class OneTimePassword(models.Model):
    """An account whose password someone else made (a site admin's reset, an account a
    site admin created) and its owner has not replaced yet.

    Signed in with it, the owner must choose a new password before anything else
    (``cutroom.accounts.middleware``); choosing one deletes the row, so the password made
    for them is used once.
    """

    user = models.OneToOneField(settings.AUTH_USER_MODEL, on_delete=models.CASCADE,
                                primary_key=True, related_name="one_time_password")
    issued_at = models.DateTimeField(default=timezone.now)

    def __str__(self):
        return f"{self.user_id}: one-time password of {self.issued_at:%Y-%m-%d %H:%M}"
