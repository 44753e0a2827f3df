"""Importing capture files from disk through the upload workflow.

Used by ``manage.py import_captures`` and ``manage.py demo``: a file on disk becomes a
capture exactly as an upload does (``do_upload_capture``: stored unchanged, duplicates
recognised by checksum, ingest and detection queued for the worker).
"""

import contextlib
import os
from dataclasses import dataclass
from pathlib import Path

from django.core.files import File

import motionlib
from motionlib.io import check_bvh
from motionlib.io.fbx import check_fbx_header
from segmentation.errors import ImportProblem
from segmentation.files import storage
from segmentation.services.captures import do_upload_capture

CAPTURE_SUFFIXES = (".bvh", ".amc", ".fbx", ".c3d", ".tsv", ".csv")


@dataclass
class Outcome:
    """What happened to one file: ``imported``, ``duplicate`` or ``failed`` (with why)."""

    path: Path
    status: str
    reason: str = ""
    capture: object = None


def find_captures(paths):
    """Capture files named by ``paths``, folders walked recursively.

    Returns (files, problems): the ``.bvh``/``.amc`` files in a stable order (each path
    in the order given, a folder's files sorted), and a failed :class:`Outcome` for each
    path that does not exist or names a file that is not a capture. Other files found
    while walking a folder (``.asf`` skeletons, notes…) are not captures and are passed by.
    """
    files, problems, seen = [], [], set()
    for given in map(Path, paths):
        if given.is_dir():
            found = sorted(p for p in given.rglob("*") if _is_capture(p))
        elif given.is_file() and _is_capture(given):
            found = [given]
        else:
            problems.append(Outcome(given, "failed", _not_a_capture(given)))
            continue
        for path in found:
            # The same file named twice (or inside two given folders) is imported once.
            if path.resolve() not in seen:
                seen.add(path.resolve())
                files.append(path)
    return files, problems


def _is_capture(path):
    return path.is_file() and path.suffix.lower() in CAPTURE_SUFFIXES


def _not_a_capture(path):
    if not path.exists():
        return f"{path}: no such file or folder"
    return (f"{path}: extension {path.suffix or '(none)'!r} is not a capture; "
            "expected .bvh, .fbx, .amc with its .asf, or points in .c3d, .tsv or .csv")


def find_asf(amc, asf=None):
    """The ASF skeleton of an AMC file.

    ``asf`` when given; otherwise ``<subject>.asf`` (the subject is the AMC name up to its
    first ``_``, CMU style: ``13_30.amc`` -> ``13.asf``) beside the AMC file, in an
    ``asf/`` folder beside it, or in a sibling ``asf/`` folder (``amc/`` and ``asf/``
    side by side, as CMU distributes them); else the only ``.asf`` beside the AMC file.
    Raises ImportProblem naming the places looked at.
    """
    amc = Path(amc)
    if asf is not None:
        if not Path(asf).is_file():
            raise ImportProblem(f"--asf {asf}: no such file")
        return Path(asf)
    subject = amc.stem.split("_")[0] + ".asf"
    places = [amc.parent / subject, amc.parent / "asf" / subject, amc.parent.parent / "asf" / subject]
    for place in places:
        if place.is_file():
            return place
    beside = sorted(p for p in amc.parent.glob("*") if p.suffix.lower() == ".asf" and p.is_file())
    if len(beside) == 1:
        return beside[0]
    looked = ", ".join(str(p) for p in places)
    raise ImportProblem(f"{amc}: no ASF skeleton found (looked for {looked}); pass --asf PATH")


def check_readable(path, asf=None, full=False):
    """Check the file's structure with motionlib under the service's input limits;
    CaptureError names the file, line and value at fault.

    A BVH's hierarchy and motion header are checked (``motionlib.io.check_bvh``: the head
    of the file only, so that importing a folder costs little more than copying it); its
    frames are read by the worker, which fails the capture naming a bad frame's line.
    ``full`` reads every frame here too (the worker then reads the file again). An FBX is
    only checked to be binary FBX: Blender reads it on the convert queue. A CMU AMC
    (small files) and a point take (C3D, TSV, CSV: read at the speed of copying) are read
    in full."""
    suffix = Path(path).suffix.lower()
    limits = storage.input_limits()
    if suffix == ".fbx":
        check_fbx_header(path)
    elif suffix == ".bvh" and not full:
        check_bvh(path, limits=limits)
    else:
        motionlib.read(path, asf=asf, limits=limits)


def import_file(project, user, path, asf=None, check=True, full_check=False):
    """Import one capture file into ``project`` as if ``user`` had uploaded it.

    Parameters
    ----------
    project : Project
    user : User or None
        Recorded as the uploader.
    path : str or PathLike
        A ``.bvh`` file, or an ``.amc`` file (its ASF found by :func:`find_asf`).
    asf : str or PathLike, optional
        The ASF to use for an AMC file instead of looking for one.
    check : bool
        Check the file's structure first (:func:`check_readable`) and refuse it if
        broken, instead of leaving the worker to mark the capture failed.
    full_check : bool
        With ``check``: read every frame too.

    Returns
    -------
    Outcome
        Never raises for a bad file: the outcome says ``failed`` and why.
    """
    path = Path(path)
    try:
        skeleton = find_asf(path, asf) if path.suffix.lower() == ".amc" else None
        if check:
            check_readable(path, skeleton, full=full_check)
        capture, created = _upload(project, user, path, skeleton)
    except (ValueError, OSError) as exc:
        return Outcome(path, "failed", _reason(path, exc))
    return Outcome(path, "imported" if created else "duplicate", capture=capture)


def _upload(project, user, path, asf):
    with open(path, "rb") as handle, _maybe_open(asf) as asf_handle:
        upload = File(handle, name=path.name)
        skeleton = File(asf_handle, name=asf.name) if asf_handle else None
        return do_upload_capture(project, user, upload, skeleton)


def _maybe_open(path):
    return contextlib.nullcontext() if path is None else open(path, "rb")  # noqa: SIM115


def _reason(path, exc):
    text = str(exc)
    if isinstance(exc, OSError):
        text = f"{exc.strerror or type(exc).__name__}: {exc.filename or path}"
    # motionlib and the upload checks name the file already; others get it prefixed.
    return text if path.name in text else f"{path}: {text}"


def relative(path):
    """``path`` relative to the working directory when inside it (shorter summaries)."""
    try:
        return os.path.relpath(path)
    except ValueError:
        return str(path)
