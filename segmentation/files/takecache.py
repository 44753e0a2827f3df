"""Parsed takes kept beside their originals, so that retraining a project does not parse
every reviewed take's text again.

A project retrains from all its reviewed takes after each submit; parsing fifty 5-minute
BVH files is about a fifth of that training. The parse of a capture never changes (an
original is never rewritten, and the cache's name carries the capture's checksum), so it
is stored once as two files under ``derived/takes/``: the channel values as a ``.npy``
(float64, exactly what the parser read; memory-mapped when read back from a local
filesystem, so fifty takes cost page cache rather than private memory) and the skeleton
and take metadata as a small ``.npz``. Nothing is pickled.

What fitting a project's cut model learnt from a reviewed capture (a study, see
``motionlib.adapt``) is stored beside it under ``derived/studies/``: one ``.npz`` per
capture, replaced when its cuts or the detector's settings change.
"""

import io
import json
import logging
import zipfile

import numpy as np
from django.core.files.base import ContentFile

from motionlib.skeleton import Skeleton
from motionlib.take import Take

log = logging.getLogger(__name__)

# Bump when the stored layout (or what the parser reads) changes: old files are ignored.
FORMAT = 1


def cache_names(capture):
    stem = f"derived/takes/v{FORMAT}/{capture.pk}-{capture.checksum[:16]}"
    return f"{stem}.channels.npy", f"{stem}.meta.npz"


def read_cached(capture, read):
    """The capture's take from its cache, else ``read(capture)`` (then cached).

    A cache that cannot be written (storage full, read-only) is logged and skipped: the
    take is still returned.
    """
    channels_name, meta_name = cache_names(capture)
    storage = capture.original.storage
    if storage.exists(meta_name) and storage.exists(channels_name):
        return _load(storage, channels_name, meta_name)
    take = read(capture)
    try:
        _store(storage, take, channels_name, meta_name)
    except OSError:
        log.exception("could not cache the parsed take of capture %s", capture.pk)
    return take


def _store(storage, take, channels_name, meta_name):
    channels = io.BytesIO()
    np.save(channels, np.ascontiguousarray(take.channels, dtype=np.float64), allow_pickle=False)
    meta = io.BytesIO()
    np.savez(meta, **_meta_arrays(take))
    # Metadata last: a reader only trusts a cache whose metadata exists. A file already
    # there (a concurrent or interrupted writer) holds the same bytes and is kept: saving
    # again would only add a renamed copy.
    for name, content in ((channels_name, channels), (meta_name, meta)):
        if not storage.exists(name):
            storage.save(name, ContentFile(content.getvalue()))


def _meta_arrays(take):
    sk = take.skeleton
    text = {
        "name": take.name, "format": take.format, "fps": take.fps, "frame_time": take.frame_time,
        "rest_pose_frame": take.rest_pose_frame, "path": take.path, "names": list(sk.names),
        "channels": [list(c) for c in sk.channels], "rotation_orders": list(sk.rotation_orders),
        "end_site_joints": [int(j) for j in sk.end_sites],
    }
    arrays = {
        "text": np.array(json.dumps(text)),
        "parents": np.asarray(sk.parents), "offsets": np.asarray(sk.offsets, dtype=np.float64),
        "end_sites": np.array([sk.end_sites[j] for j in sk.end_sites], dtype=np.float64).reshape(-1, 3),
    }
    if sk.axes is not None:
        arrays["axes"] = np.asarray(sk.axes, dtype=np.float64)
    return arrays


def _read_npz(storage, name):
    """The arrays of a stored ``.npz`` (nothing pickled)."""
    with storage.open(name, "rb") as handle:
        with np.load(io.BytesIO(handle.read()), allow_pickle=False) as data:
            return {key: data[key] for key in data.files}


def _load(storage, channels_name, meta_name):
    meta = _read_npz(storage, meta_name)
    text = json.loads(str(meta["text"]))
    skeleton = Skeleton(
        names=text["names"], parents=meta["parents"], offsets=meta["offsets"],
        channels=[tuple(c) for c in text["channels"]], rotation_orders=text["rotation_orders"],
        axes=meta.get("axes"),
        end_sites=dict(zip(text["end_site_joints"], meta["end_sites"], strict=True)),
    )
    return Take(
        name=text["name"], format=text["format"], fps=text["fps"], frame_time=text["frame_time"],
        channels=_channels(storage, channels_name), skeleton=skeleton,
        rest_pose_frame=text["rest_pose_frame"], path=text["path"],
    )


def _channels(storage, name):
    try:
        return np.load(storage.path(name), mmap_mode="r", allow_pickle=False)
    except NotImplementedError:
        with storage.open(name, "rb") as handle:
            return np.load(io.BytesIO(handle.read()), allow_pickle=False)


def example_key(capture):
    """What identifies a capture's content: its id and its original's checksum."""
    return f"{capture.pk}-{capture.checksum[:16]}"


class StoredStudies:
    """``motionlib.adapt.Studies`` in the media storage: one ``.npz`` per capture holding
    the study and the key it was made for. A file that cannot be read is a miss (the take
    is analysed again); one that cannot be written is logged and skipped."""

    def __init__(self, storage):
        self.storage = storage

    @staticmethod
    def name(example_key):
        return f"derived/studies/v{FORMAT}/{example_key}.npz"

    def load(self, example_key, study_key):
        name = self.name(example_key)
        try:
            if not self.storage.exists(name):
                return None
            arrays = _read_npz(self.storage, name)
        except (OSError, ValueError, EOFError, zipfile.BadZipFile):
            log.warning("could not read the stored study %s; analysing the take again", name)
            return None
        if str(arrays.pop("study_key", "")) != study_key:
            return None
        return arrays

    def save(self, example_key, study_key, arrays):
        name = self.name(example_key)
        content = io.BytesIO()
        np.savez(content, study_key=np.array(study_key), **arrays)
        try:
            if self.storage.exists(name):
                self.storage.delete(name)
            self.storage.save(name, ContentFile(content.getvalue()))
        except OSError:
            log.exception("could not store the study of %s", example_key)
