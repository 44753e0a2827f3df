"""Stored files go with the rows that name them.

A capture deleted (in the admin, or with its project) takes its original, its ASF, its
converted take and its positions along, and a detection run its signals, once the delete
commits. A job that wrote a file for a row that was deleted meanwhile (or whose claim
another worker took over) deletes that file itself when its result finds no row to go to
(``forget``): otherwise a capture deleted mid-ingest would leave its positions behind.

A file is deleted only when no row names it any more: the animations of one FBX share its
stored original.
"""

import logging

from django.db import transaction
from django.db.models import Q
from django.db.models.signals import post_delete

from segmentation.models import Capture, DetectionRun

log = logging.getLogger(__name__)

CAPTURE_FILES = ("original", "asf", "converted", "positions")


def forget(fieldfile):
    """Delete ``fieldfile`` (a job's output) once committed, unless a row names it."""
    if fieldfile and fieldfile.name:
        _after_commit(fieldfile.storage, [fieldfile.name])


def unused(names):
    """Those of ``names`` that no capture or detection run names."""
    names = [n for n in names if n]
    if not names:
        return []
    named = Q()
    for field in CAPTURE_FILES:
        named |= Q(**{f"{field}__in": names})
    used = set()
    for row in Capture.objects.filter(named).values_list(*CAPTURE_FILES):
        used.update(row)
    used.update(DetectionRun.objects.filter(signals__in=names).values_list("signals", flat=True))
    return [n for n in names if n not in used]


def _after_commit(storage, names):
    def delete():
        for name in unused(names):
            try:
                storage.delete(name)
            except OSError:
                log.exception("could not delete the stored file %s", name)

    transaction.on_commit(delete)


def _capture_deleted(sender, instance, **kwargs):
    fields = [getattr(instance, f) for f in CAPTURE_FILES]
    _after_commit(fields[0].storage, [f.name for f in fields if f])


def _run_deleted(sender, instance, **kwargs):
    if instance.signals:
        _after_commit(instance.signals.storage, [instance.signals.name])


def connect():
    post_delete.connect(_capture_deleted, sender=Capture, dispatch_uid="cleanup-capture")
    post_delete.connect(_run_deleted, sender=DetectionRun, dispatch_uid="cleanup-run")
