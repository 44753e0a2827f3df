"""Reading and writing capture files through Django's storage (filesystem or S3-like)."""

import contextlib
import io
import os
import shutil
import tempfile

import numpy as np
from django.core.files.base import ContentFile


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
    """Store ``array`` as a ``.npy`` file in ``fieldfile`` (the model is not saved)."""
    buffer = io.BytesIO()
    np.save(buffer, array, allow_pickle=False)
    fieldfile.save(name, ContentFile(buffer.getvalue()), save=False)


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


def load_npz(fieldfile):
    """name -> array of a stored ``.npz``."""
    with fieldfile.storage.open(fieldfile.name, "rb") as handle:
        with np.load(io.BytesIO(handle.read()), allow_pickle=False) as data:
            return {key: data[key] for key in data.files}
