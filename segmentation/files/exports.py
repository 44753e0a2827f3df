"""Library clips as files: BVH (written here), FBX and glTF binary, C3D and joint-position CSV
for point takes (same points, rate and gaps), and bulk export as a zip archive with a manifest.

FBX, and glTF cut from an FBX original, run Blender in a child process of the calling process
(``motionlib.io.blender``; nothing here imports it); glTF of any other take (no mesh) is
written by ``motionlib.io.gltf`` in this process. A clip of a capture read from FBX is cut from
its stored original, so it keeps the original's armature and bone names; any other becomes a
new armature. FBX and glTF
clips are in metres by :func:`motionlib.io.units.length_unit`; BVH clips keep the take's numbers.

Every clip holds exactly the frames :func:`clip_range` names, in every format, and the manifest
says which (``start``, ``stop``, ``frames``) and in what length unit (``unit``).
"""

import contextlib
import csv
import io
import itertools
import json
import logging
import os
import re
import tempfile
import zipfile
from pathlib import PurePath

from django.db.models import Q

import motionlib
from motionlib.errors import MotionlibError
from motionlib.io.export import write_clips
from motionlib.io.text import spreadsheet_safe
from motionlib.io.units import length_unit
from segmentation.errors import CutroomError, ExportFormatError, internal_error
from segmentation.files import storage
from segmentation.files.storage import read_take

log = logging.getLogger(__name__)

EXPORT_FORMATS = {"bvh": "BVH", "fbx": "FBX", "glb": "glTF binary", "c3d": "C3D",
                  "csv": "joint-position CSV"}
CONTENT_TYPES = {"bvh": "application/octet-stream", "fbx": "application/octet-stream",
                 "glb": "model/gltf-binary", "c3d": "application/octet-stream",
                 "csv": "text/csv"}

MAX_EXPORT_SEGMENTS = 5000
# Every entry of an export archive carries this time stamp, not the time of the export: the
# same library exports to the same bytes (a restored backup is checked that way).
ZIP_ENTRY_TIME = (1980, 1, 1, 0, 0, 0)
POINT_CAPTURE_FORMATS = ("c3d", "tsv", "csv")


def formats_for(capture):
    """The export formats that apply to a capture's segments: points as C3D or CSV, joint
    rotations as BVH, FBX or glTF (``motionlib.io.export.check_export_format``)."""
    return ["c3d", "csv"] if capture.format in POINT_CAPTURE_FORMATS else ["bvh", "fbx", "glb"]


def writable_in(segments, fmt):
    """The segments of a queryset whose clips ``fmt`` writes (:func:`formats_for`)."""
    points = Q(capture__format__in=POINT_CAPTURE_FORMATS)
    return segments.filter(points) if fmt in ("c3d", "csv") else segments.exclude(points)


def left_out_note(count, fmt):
    """What ``errors.txt`` says of the ``count`` matching segments of the other kind."""
    kind, formats = (("joint-rotation takes", "BVH, FBX or glTF") if fmt in ("c3d", "csv")
                     else ("point takes", "C3D or CSV"))
    return (f"{count} segment{'s are' if count != 1 else ' is'} not in this archive: "
            f"segments of {kind} export as {formats}, not {EXPORT_FORMATS[fmt]}")


def check_format(fmt):
    fmt = (fmt or "bvh").lower()
    if fmt not in EXPORT_FORMATS:
        raise ExportFormatError(f"format: {fmt!r} is not an export format; choose one of "
                                f"{', '.join(EXPORT_FORMATS)}")
    return fmt


def file_stem(segment):
    """``capture_label_start-stop`` with safe characters only (``#animation`` kept readable)."""
    stem = PurePath(segment.capture.name.replace("#", "_")).stem
    if "#" in segment.capture.name:  # "take.fbx#walk": the animation after the file stem
        base, animation = segment.capture.name.split("#", 1)
        stem = f"{PurePath(base).stem}_{animation}"
    return f"{slug(stem)}_{slug(segment.label.name)}_{segment.start}-{segment.stop}"


def clip_files(capture, take, segments, fmt):
    """Yield ``(segment, file name, bytes)`` for each segment of one capture.

    The segments' clips are written in one go (an FBX original is imported once).
    """
    segments = list(segments)
    with tempfile.TemporaryDirectory(prefix="cutroom-export-") as folder, \
            _original(capture, take) as original:
        names = [f"{file_stem(s)}.{fmt}" for s in segments]
        clips = [(*clip_range(take, s), os.path.join(folder, f"{i}.{fmt}"))
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


def slug(text):
    return re.sub(r"[^A-Za-z0-9_]+", "-", str(text)).strip("-") or "untitled"


def file_name(segment):
    """``capture_label_start-stop.bvh`` with safe characters only."""
    stem = PurePath(segment.capture.name).stem
    return f"{slug(stem)}_{slug(segment.label.name)}_{segment.start}-{segment.stop}.bvh"


def clip_range(take, segment):
    """The capture frames ``(start, stop)`` the segment's clip holds, in every format.

    A cgspeed BVH's added T-pose frame (``take.rest_pose_frame``) is not part of the
    performance, so a clip that starts on or before it starts just after it.
    """
    start = segment.start
    if take.rest_pose_frame is not None and start <= take.rest_pose_frame < segment.stop - 1:
        start = take.rest_pose_frame + 1
    return start, segment.stop


def bvh_text(take, segment):
    """The segment's frames (:func:`clip_range`) as BVH with the take's own hierarchy and
    frame time."""
    start, stop = clip_range(take, segment)
    out = io.StringIO()
    motionlib.write_bvh(take, out, start=start, stop=stop)
    return out.getvalue()


def unit_text(take, fmt):
    """The length unit of a clip in ``fmt``, for the manifest."""
    if fmt == "bvh":
        return "the capture's own (BVH numbers as in the original)"
    if fmt in ("c3d", "csv"):
        unit = getattr(take, "unit", "") or "as in the original"
        return f"the capture's own ({unit})"
    return f"metre; the capture's unit taken as {length_unit(take).describe()}"


def unique_name(name, segment, used):
    """``name``, or with the annotator (then the segment id) added if the archive already
    holds it: two annotators' versions of one range and label would share a name."""
    if name in used:
        stem, dot, ext = name.rpartition(".")
        who = slug(segment.annotator.username) if segment.annotator else "gold"
        name = f"{stem}_{who}{dot}{ext}"
        if name in used:
            name = f"{stem}_{who}_{segment.pk}{dot}{ext}"
    used.add(name)
    return name


def manifest_row(segment, name, fmt, take, unit):
    """One clip of the archive: ``start``/``stop`` are the capture frames the file holds
    (:func:`clip_range`), ``frames`` how many; ``unit`` its length unit (:func:`unit_text`)."""
    start, stop = clip_range(take, segment)
    return {
        "file": name, "format": fmt, "segment": segment.pk, "capture": segment.capture.name,
        "capture_id": segment.capture_id, "start": start, "stop": stop, "frames": stop - start,
        "unit": unit, "label": segment.label.name, "gold": segment.is_gold,
        "annotator": segment.annotator.username if segment.annotator else None,
        "agreement": segment.agreement,
        # The segment's attribute values by name (the list prefetches them).
        "attributes": {v.attribute.name: v.attribute.shown(v.value)
                       for v in sorted(segment.attribute_values.all(),
                                       key=lambda v: (v.attribute.position, v.attribute_id))},
    }


class _Sink:
    """A write-only file for ``zipfile``: it collects bytes until ``drain`` hands them out."""

    def __init__(self):
        self.parts = []

    def write(self, data):
        self.parts.append(bytes(data))
        return len(data)

    def flush(self):
        pass

    def drain(self):
        data, self.parts = b"".join(self.parts), []
        return data


def stream_zip(segments, fmt="bvh", left_out=0):
    """Yield a zip archive of one clip per segment (BVH, FBX or glTF binary: ``fmt``) plus
    ``manifest.csv`` and ``manifest.json``; ``left_out`` segments of the other kind of take
    (:func:`writable_in`) are counted in ``errors.txt``.

    ``segments`` should be ordered by capture so each take is read once; the archive is
    written as it goes (at most one take and one capture's clips are in memory). A take that
    cannot be read any more cannot turn into an error response once streaming has begun: its
    segments are left out and ``errors.txt`` says why.
    """
    # An empty first chunk sends the response's headers (the clip count the page shows)
    # before the first take is read and its clips written.
    yield b""
    sink = _Sink()
    manifest, errors, used = [], [left_out_note(left_out, fmt)] if left_out else [], set()
    with zipfile.ZipFile(sink, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for _, group in itertools.groupby(segments, key=lambda s: s.capture_id):
            group = list(group)
            capture = group[0].capture
            try:
                take = read_take(capture)
                unit = unit_text(take, fmt)
                for segment, name, data in _clips(capture, take, group, fmt):
                    name = unique_name(name, segment, used)
                    archive.writestr(_entry(name), data)
                    manifest.append(manifest_row(segment, name, fmt, take, unit))
                    yield sink.drain()
            except (MotionlibError, CutroomError) as exc:
                errors.append(f"capture {capture.pk} ({capture.name}): {exc}")
            except Exception:
                # Not the take's fault: logged with its traceback, named by its reference.
                reference = internal_error(f"export of capture {capture.pk}", log)
                errors.append(f"capture {capture.pk} ({capture.name}): internal error "
                              f"(reference {reference})")
        archive.writestr(_entry("manifest.json"), json.dumps(manifest, indent=1))
        archive.writestr(_entry("manifest.csv"), _csv(manifest))
        if errors:
            archive.writestr(_entry("errors.txt"), "\n".join(errors) + "\n")
    yield sink.drain()


def _entry(name):
    info = zipfile.ZipInfo(name, date_time=ZIP_ENTRY_TIME)
    info.compress_type, info.external_attr = zipfile.ZIP_DEFLATED, 0o644 << 16
    return info


def _clips(capture, take, segments, fmt):
    if fmt == "bvh":
        return ((s, file_name(s), bvh_text(take, s)) for s in segments)
    return clip_files(capture, take, segments, fmt)


def _csv(rows):
    """The manifest as CSV: one ``attribute:<name>`` column per segment attribute any row
    carries (a boolean as true/false, an unset value empty)."""
    out = io.StringIO()
    fields = ["file", "format", "segment", "capture", "capture_id", "start", "stop", "frames",
              "unit", "label", "gold", "annotator", "agreement"]
    names = list(dict.fromkeys(name for row in rows for name in row.get("attributes", {})))
    writer = csv.DictWriter(out, fieldnames=fields + [f"attribute:{n}" for n in names])
    # Names and values typed by people (capture, label, annotator, attribute names, options
    # and notes) open as text, never as formulas.
    writer.writerow({k: spreadsheet_safe(k) for k in writer.fieldnames})
    for row in rows:
        flat = {k: v for k, v in row.items() if k != "attributes"}
        flat.update({f"attribute:{n}": _cell(v) for n, v in row.get("attributes", {}).items()})
        writer.writerow({k: spreadsheet_safe(v) if isinstance(v, str) else v for k, v in flat.items()})
    return out.getvalue()


def _cell(value):
    return str(value).lower() if isinstance(value, bool) else value
