"""The key of each account's username (``accounts.usernames``), stored and unique."""

from django.conf import settings
from django.db import models


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

    class Meta:
        db_table = "segmentation_usernamekey"  # made when it was a model of that app

    def __str__(self):
        return f"{self.user_id}: {(self.digest or '-')[:8]}…"

