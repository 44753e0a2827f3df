"""Row locks by name, for counting attempts against a limit atomically.

``hold(names)`` must run inside ``transaction.atomic()``: it locks one ``ThrottleLock``
row per name (made on first use) until the transaction ends. Names are locked in sorted
order, so two transactions holding overlapping names never wait for each other in a
cycle. On SQLite the service's IMMEDIATE transactions already run one at a time; the
rows make the same code hold on PostgreSQL, where transactions run side by side.
"""

import hashlib
from datetime import timedelta

from django.db import transaction
from django.utils import timezone

from accounts.models import ThrottleLock

# A lock row unused this long is deleted (the next use makes it again).
IDLE = timedelta(days=1)


def digest(text):
    return hashlib.sha256(text.encode("utf-8", "surrogatepass")).hexdigest()


def hold(names):
    """Lock the rows of ``names`` (any text; stored as digests) for this transaction."""
    if not transaction.get_connection().in_atomic_block:
        raise RuntimeError("locks.hold needs a transaction (transaction.atomic())")
    keys = sorted({digest(name) for name in names})
    now = timezone.now()
    while True:
        ThrottleLock.objects.bulk_create([ThrottleLock(key=k, used_at=now) for k in keys],
                                         ignore_conflicts=True)
        locked = list(ThrottleLock.objects.select_for_update().filter(key__in=keys).order_by("key"))
        if len(locked) == len(keys):
            break
        # A row went between the insert and the lock (deleted as idle): make it again.
    ThrottleLock.objects.filter(key__in=keys).update(used_at=now)


def forget_idle():
    ThrottleLock.objects.filter(used_at__lt=timezone.now() - IDLE).delete()
