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
from segmentation.files import cleanup, storage
from segmentation.models import Capture
from segmentation.services import jobs, quotas
from segmentation.services.jobs import Kind, enqueue, register

log = logging.getLogger(__name__)


def convert_capture(capture):
    """Read a claimed FBX capture with Blender and queue the ingest of each animation.

    A file Blender cannot read (no armature, no animation, damaged, Blender crashing or
    hanging on it) marks the capture failed with a reason a person can act on; so does a
    file uploaded through the API with more animations than its uploader may still upload
    this hour (each animation counts as an upload).
    """
    jobs.guard(CONVERT, capture)


def _convert(capture):
    with storage.local_path(capture.original) as path:
        takes = read_fbx_all(path, limits=storage.input_limits())
    several = len(takes) > 1
    first, rest = takes[0], takes[1:]
    _check_rate(capture, len(takes))  # before writing anything for a file that is refused
    capture.converted.save("take.npz", ContentFile(take_bytes(first)), save=False)
    siblings = [s for s in (new_animation(capture, take) for take in rest) if s is not None]
    with transaction.atomic():
        # Counted again, and added, under the uploader's lock: a short transaction (the
        # files are written), since on SQLite it holds up every writer.
        _check_rate(capture, len(takes), locked=True)
        handed_over = Capture.objects.filter(
            pk=capture.pk, status="processing", claim_token=capture.claim_token
        ).update(
            status="queued", claim_token="", claimed_at=timezone.now(),
            converted=capture.converted.name, animation=first.animation or "",
            name=animation_name(capture.name, first) if several else capture.name,
        )
        if handed_over:
            enqueue("ingest", capture.pk)
            for sibling in siblings:
                add_animation(sibling)
    if not handed_over:
        # Deleted meanwhile, or another worker took this capture over (it converts it
        # itself): nothing names the files just written.
        cleanup.forget(capture.converted)
        for sibling in siblings:
            sibling.converted.delete(save=False)


def _check_rate(capture, animations, locked=False):
    """Every animation of a file uploaded through the API counts as an upload."""
    if not capture.rate_limited or capture.uploaded_by is None:
        return
    if locked:
        quotas.lock(user=capture.uploaded_by)
    quotas.check_upload_rate(capture.uploaded_by, animations, fbx=capture)


def animation_name(file_name, take):
    """``file.fbx#animation`` (the file name as uploaded, without a previous suffix)."""
    return f"{file_name.split('#', 1)[0]}#{take.animation}"


def new_animation(capture, take):
    """An unsaved capture for another animation of ``capture``'s file, sharing its stored
    original, with its converted take written; None if a conversion that ran before added
    it already (its checksum is the file's with the animation name)."""
    digest = hashlib.sha256(f"{capture.checksum}#{take.animation}".encode()).hexdigest()
    if Capture.objects.filter(project=capture.project, checksum=digest).exists():
        return None
    sibling = Capture(
        project=capture.project, uploaded_by=capture.uploaded_by, source=capture,
        name=animation_name(capture.name, take), format="fbx", checksum=digest,
        animation=take.animation or "", original=capture.original.name,
    )
    sibling.converted.save("take.npz", ContentFile(take_bytes(take)), save=False)
    return sibling


def add_animation(sibling):
    """Save ``new_animation``'s capture and queue its ingest (idempotent)."""
    try:
        with transaction.atomic():
            sibling.save()
            enqueue("ingest", sibling.pk)
    except IntegrityError:
        log.info("animation %s of capture %s already added", sibling.animation, sibling.source_id)


# FBX conversion runs Blender: its own queue, served by its own worker.
CONVERT = register(Kind("convert", Capture, "Conversion", _convert, "CUTROOM_CONVERT_TIME_LIMIT",
                        queue="CUTROOM_CONVERT_QUEUE"))
