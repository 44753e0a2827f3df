"""FBX conversion: Blender reads the stored original once; each animation becomes a capture.

Runs on the ``convert`` queue (``tasks.convert``), in a worker whose Blender process stays up
between files. The converted take is saved beside the original (``Capture.converted``) and the
capture goes back to the queue for the usual ingest and detection, which never need Blender.
"""

import hashlib
import logging

from django.core.files.base import ContentFile
from django.db import IntegrityError, transaction
from django.utils import timezone

from motionlib.io.fbx import read_fbx_all
from motionlib.io.npz import take_bytes
from segmentation import storage
from segmentation.models import Capture
from segmentation.services.captures import FILE_AT_FAULT, _guarded
from segmentation.services.jobs import enqueue

log = logging.getLogger(__name__)


def convert_capture(capture):
    """Read a claimed FBX capture with Blender and queue the ingest of each animation.

    A file Blender cannot read (no armature, no animation, damaged, Blender crashing or
    hanging on it) marks the capture failed with a reason a person can act on.
    """
    _guarded(capture, "Conversion", lambda: _convert(capture), input_fault=FILE_AT_FAULT)


def _convert(capture):
    with storage.local_path(capture.original) as path:
        takes = read_fbx_all(path)
    several = len(takes) > 1
    first, rest = takes[0], takes[1:]
    capture.converted.save("take.npz", ContentFile(take_bytes(first)), save=False)
    with transaction.atomic():
        handed_over = Capture.objects.filter(
            pk=capture.pk, status="processing", claim_token=capture.claim_token
        ).update(
            status="queued", claim_token="", claimed_at=timezone.now(),
            converted=capture.converted.name, animation=first.animation or "",
            name=animation_name(capture.name, first) if several else capture.name,
        )
        if not handed_over:
            return  # another worker took this capture over; it converts it itself
        enqueue("ingest", capture.pk)
    for take in rest:
        add_animation(capture, take)


def animation_name(file_name, take):
    """``file.fbx#animation`` (the file name as uploaded, without a previous suffix)."""
    return f"{file_name.split('#', 1)[0]}#{take.animation}"


def add_animation(capture, take):
    """A capture for another animation of ``capture``'s file, sharing its stored original.

    Idempotent: a conversion that runs again finds the captures it made the first time (their
    checksum is the file's with the animation name).
    """
    digest = hashlib.sha256(f"{capture.checksum}#{take.animation}".encode()).hexdigest()
    if Capture.objects.filter(project=capture.project, checksum=digest).exists():
        return
    sibling = Capture(
        project=capture.project, uploaded_by=capture.uploaded_by, source=capture,
        name=animation_name(capture.name, take), format="fbx", checksum=digest,
        animation=take.animation or "", original=capture.original.name,
    )
    sibling.converted.save("take.npz", ContentFile(take_bytes(take)), save=False)
    try:
        with transaction.atomic():
            sibling.save()
            enqueue("ingest", sibling.pk)
    except IntegrityError:
        log.info("animation %s of capture %s already added", take.animation, capture.pk)
