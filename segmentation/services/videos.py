"""Reference videos of a capture: upload (checked, checksummed, counted in the quotas),
alignment with the take, removal."""

import contextlib
import hashlib
import os
import tempfile

from django.conf import settings
from django.db import IntegrityError, transaction
from django.utils import timezone

from motionlib.errors import shorten
from segmentation.errors import CutroomError, NotAllowed, UploadError, UploadTooLarge
from segmentation.files import video as videofiles
from segmentation.models import ReferenceVideo
from segmentation.services import quotas
from segmentation.services.captures import stored_name


def max_video_bytes():
    return settings.CUTROOM_MAX_VIDEO_MB * 1024 * 1024


def check_may_manage(capture, user):
    """NotAllowed (403) unless ``user`` may add, align and remove the capture's videos."""
    if not ReferenceVideo.may_manage(capture.project, user):
        raise NotAllowed("Only the project's reviewers and admins add, align and remove "
                         "reference videos; you annotate in this project.")


def check_size(name, size):
    """UploadError for an empty file, UploadTooLarge past CUTROOM_MAX_VIDEO_MB."""
    if size == 0:
        raise UploadError(f"file: {shorten(name)} is empty (0 bytes)")
    if size > max_video_bytes():
        raise UploadTooLarge(
            f"file: {shorten(name)} is {size / 2**20:.1f} MB; the limit for a video is "
            f"{settings.CUTROOM_MAX_VIDEO_MB} MB (CUTROOM_MAX_VIDEO_MB)")


def do_upload_video(capture, user, upload):
    """Check, store and record a video of ``capture`` uploaded by ``user``.

    Returns (video, created); the same file uploaded again to the same capture returns the
    stored one with ``created=False``. Refusals name the file and the reason: not a video,
    one a browser cannot play (``segmentation.files.video``), too large, over a quota.
    """
    check_may_manage(capture, user)
    check_size(upload.name, upload.size)
    with _local_copy(upload) as path:
        facts = videofiles.inspect(path, upload.name)
    digest = _checksum(upload)
    existing = capture.videos.filter(checksum=digest).first()
    if existing:
        return existing, False
    project = capture.project
    quotas.check_storage(project, user, upload.size)  # before writing; again under the locks
    video = ReferenceVideo(
        capture=capture, uploaded_by=user, name=upload.name, checksum=digest,
        stored_bytes=upload.size, container=facts.container, codec=facts.codec,
        duration=facts.duration, fps=facts.fps, width=facts.width, height=facts.height)
    video.file.save(_stored_name(upload.name, facts.container), upload, save=False)
    try:
        with transaction.atomic():
            quotas.lock(project, user)
            quotas.check_storage(project, user, upload.size)
            video.save()
    except IntegrityError:
        # The same file arrived twice at once; the other request stored it.
        video.file.storage.delete(video.file.name)
        return capture.videos.get(checksum=digest), False
    except CutroomError:
        video.file.storage.delete(video.file.name)
        raise
    return video, True


def do_set_offset(video, user, offset_s):
    """Save where ``video`` sits against its take (seconds; see ReferenceVideo)."""
    check_may_manage(video.capture, user)
    video.offset_s = ReferenceVideo.check_offset(offset_s)
    video.offset_set_by, video.offset_set_at = user, timezone.now()
    video.save(update_fields=["offset_s", "offset_set_by", "offset_set_at"])
    return video


def do_delete_video(video, user):
    """Remove a video and (once committed) its stored file."""
    check_may_manage(video.capture, user)
    with transaction.atomic():
        video.delete()


def _checksum(upload):
    digest = hashlib.sha256()
    for chunk in upload.chunks():
        digest.update(chunk)
    return digest.hexdigest()


def _stored_name(name, container):
    """The stored file's name: the upload's, with the extension of what it really is."""
    stem = os.path.splitext(stored_name(name))[0]
    return f"{stem}.{container}"


@contextlib.contextmanager
def _local_copy(upload):
    """A path to the upload's bytes: its temporary file when Django streamed it to disk,
    else a copy of the bytes held in memory."""
    if hasattr(upload, "temporary_file_path"):
        yield upload.temporary_file_path()
        return
    with tempfile.NamedTemporaryFile(prefix="cutroom-video-") as copy:
        for chunk in upload.chunks():
            copy.write(chunk)
        copy.flush()
        yield copy.name
