"""Named row locks: one row per key that counting against a limit locks (``accounts.locks``)."""

from django.db import models
from django.utils import timezone


class ThrottleLock(models.Model):
    """One row per throttled key (a username, an address, an invitee...), locked while
    an attempt is counted against that key and recorded.

    Counting and recording under the row lock make them one step: simultaneous attempts
    (threads or processes, on PostgreSQL or SQLite) are counted one after the other, so
    no more of them get through than the limit allows. ``used_at`` lets unused rows go.
    """

    key = models.CharField(max_length=64, unique=True)
    used_at = models.DateTimeField(default=timezone.now, db_index=True)

    class Meta:
        db_table = "segmentation_throttlelock"  # made when it was a model of that app

    def __str__(self):
        return f"{self.key[:8]}… used {self.used_at:%Y-%m-%d %H:%M:%S}"
