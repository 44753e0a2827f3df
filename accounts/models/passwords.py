"""Which accounts still sign in with a one-time password."""

from django.conf import settings
from django.db import models
from django.utils import timezone


class OneTimePassword(models.Model):
    """An account whose password someone else made (a site admin's reset, an account a
    site admin created) and its owner has not replaced yet.

    Signed in with it, the owner must choose a new password before anything else
    (``accounts.middleware``); choosing one deletes the row, so the password made
    for them is used once.
    """

    user = models.OneToOneField(settings.AUTH_USER_MODEL, on_delete=models.CASCADE,
                                primary_key=True, related_name="one_time_password")
    issued_at = models.DateTimeField(default=timezone.now)

    def __str__(self):
        return f"{self.user_id}: one-time password of {self.issued_at:%Y-%m-%d %H:%M}"
