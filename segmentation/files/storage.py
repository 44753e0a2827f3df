"""Reading and writing capture files through Django's storage (filesystem or S3-like), and
reading a capture's take from its stored original."""

import contextlib
import io
import os
import shutil
import tempfile

import numpy as np
from django.conf import settings
from django.core.files.base import ContentFile, File

import motionlib
from motionlib.io.npz import load_take
from motionlib.take import Limits
from segmentation.errors import NotReady


@contextlib.contextmanager
def local_path(fieldfile):
    """A local filesystem path for a stored file, keeping its name and extension.

    motionlib reads paths; a remote storage backend gets a temporary local copy.
    """
    try:
        yield fieldfile.storage.path(fieldfile.name)
        return
    except NotImplementedError:
        pass
    with tempfile.TemporaryDirectory(prefix="cutroom-") as folder:
        path = os.path.join(folder, os.path.basename(fieldfile.name))
        with fieldfile.storage.open(fieldfile.name, "rb") as src, open(path, "wb") as dst:
            shutil.copyfileobj(src, dst)
        yield path


def save_npy(fieldfile, name, array):
    """Store ``array`` as a ``.npy`` file in ``fieldfile`` (the model is not saved).

    Written once, to a scratch file beside the media root, which a filesystem storage then
    moves into place (an hour of positions, 160 MB, is neither held in a buffer nor copied
    again); another storage reads the scratch file.
    """
    folder = settings.MEDIA_ROOT if os.path.isdir(settings.MEDIA_ROOT) else None
    handle, path = tempfile.mkstemp(dir=folder, prefix=".npy-", suffix=".upload")
    try:
        with os.fdopen(handle, "w+b") as scratch:
            np.save(scratch, array, allow_pickle=False)
            scratch.seek(0)
            fieldfile.save(name, _Scratch(scratch, path), save=False)
    finally:
        if os.path.exists(path):
            os.remove(path)


class _Scratch(File):
    """A written scratch file that storage may move instead of copying (Django's
    ``FileSystemStorage`` moves whatever has a ``temporary_file_path``)."""

    def __init__(self, scratch, path):
        super().__init__(scratch, name=os.path.basename(path))
        self.path = path

    def temporary_file_path(self):
        return self.path


def save_npz(fieldfile, name, arrays):
    buffer = io.BytesIO()
    np.savez_compressed(buffer, **arrays)
    fieldfile.save(name, ContentFile(buffer.getvalue()), save=False)


def load_npy(fieldfile):
    """The stored array, memory-mapped when the storage is a local filesystem."""
    try:
        return np.load(fieldfile.storage.path(fieldfile.name), mmap_mode="r", allow_pickle=False)
    except NotImplementedError:
        with fieldfile.storage.open(fieldfile.name, "rb") as handle:
            return np.load(io.BytesIO(handle.read()), allow_pickle=False)


def float32_blocks(array, start, stop, frames):
    """The rows ``start .. stop - 1`` of ``array`` (a stored, maybe memory-mapped array) as
    little-endian float32 bytes, ``frames`` rows at a time: an answer streams an hour of
    positions without holding more than one block in memory."""
    for first in range(start, stop, frames):
        yield np.ascontiguousarray(array[first:min(first + frames, stop)], "<f4").tobytes()


def load_npz(fieldfile):
    """name -> array of a stored ``.npz``."""
    with fieldfile.storage.open(fieldfile.name, "rb") as handle:
        with np.load(io.BytesIO(handle.read()), allow_pickle=False) as data:
            return {key: data[key] for key in data.files}


def input_limits():
    """motionlib's limits on what a capture may hold, with those set in the settings, and
    at least two frames (one pose has no motion to segment or review)."""
    overrides = {
        "max_joints": settings.CUTROOM_MAX_JOINTS,
        "max_frames": settings.CUTROOM_MAX_FRAMES,
        "max_values": settings.CUTROOM_MAX_FRAME_VALUES,
        "max_joint_frames": settings.CUTROOM_MAX_JOINT_FRAMES,
        "max_expansion": settings.CUTROOM_MAX_EXPANSION,
    }
    return Limits(min_frames=2, **{k: v for k, v in overrides.items() if v is not None})


def read_take(capture):
    """The parsed take of a capture's stored original (BVH, or AMC with its ASF), or of the
    take the convert worker saved for an FBX."""
    if capture.converted:
        with capture.converted.open("rb") as handle:
            return load_take(io.BytesIO(handle.read()), path=capture.name)
    if capture.needs_conversion:
        raise NotReady(f"capture {capture.pk} is an FBX not converted yet")
    limits = input_limits()
    with local_path(capture.original) as path:
        if capture.asf:
            with local_path(capture.asf) as asf_path:
                return motionlib.read(path, asf=asf_path, limits=limits)
        return motionlib.read(path, limits=limits)
