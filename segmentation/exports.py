"""Library clips as files: BVH (written here), FBX and glTF binary (written by Blender).

FBX and glTF run Blender in a child process of the calling process (``motionlib.io.blender``;
nothing here imports it). A clip of a capture read from FBX is cut from its stored original, so
it keeps the original's armature and bone names; any other becomes a new armature.
"""

import contextlib
import os
import tempfile
from pathlib import PurePath

from motionlib.io.export import write_clips
from segmentation import storage

EXPORT_FORMATS = {"bvh": "BVH", "fbx": "FBX", "glb": "glTF binary"}
CONTENT_TYPES = {"bvh": "application/octet-stream", "fbx": "application/octet-stream",
                 "glb": "model/gltf-binary"}


class ExportFormatError(ValueError):
    """An export format the library does not write."""


def check_format(fmt):
    fmt = (fmt or "bvh").lower()
    if fmt not in EXPORT_FORMATS:
        raise ExportFormatError(f"format: {fmt!r} is not an export format; choose one of "
                                f"{', '.join(EXPORT_FORMATS)}")
    return fmt


def file_stem(segment):
    """``capture_label_start-stop`` with safe characters only (``#animation`` kept readable)."""
    from segmentation.library import slug

    stem = PurePath(segment.capture.name.replace("#", "_")).stem
    if "#" in segment.capture.name:  # "take.fbx#walk": the animation after the file stem
        base, animation = segment.capture.name.split("#", 1)
        stem = f"{PurePath(base).stem}_{animation}"
    return f"{slug(stem)}_{slug(segment.label_name)}_{segment.start}-{segment.stop}"


def clip_files(capture, take, segments, fmt):
    """Yield ``(segment, file name, bytes)`` for each segment of one capture.

    The segments' clips are written in one go (an FBX original is imported once).
    """
    segments = list(segments)
    with tempfile.TemporaryDirectory(prefix="cutroom-export-") as folder, \
            _original(capture, take) as original:
        names = [f"{file_stem(s)}.{fmt}" for s in segments]
        clips = [(s.start, s.stop, os.path.join(folder, f"{i}.{fmt}"))
                 for i, s in enumerate(segments)]
        write_clips(take, clips, format=fmt, original=original)
        for segment, name, (_, _, path) in zip(segments, names, clips, strict=True):
            with open(path, "rb") as handle:
                yield segment, name, handle.read()


@contextlib.contextmanager
def _original(capture, take):
    """A local path of the stored original when the clip is cut from it (FBX), else None."""
    if take.format != "fbx":
        yield None
        return
    with storage.local_path(capture.original) as path:
        yield path
