"""Reading and writing capture files: BVH, CMU ASF/AMC and FBX (through Blender, on demand),
and point takes: C3D markers, Qualisys TSV markers and joint-position CSV."""

from __future__ import annotations

import os
from pathlib import Path

from motionlib.errors import CaptureError
from motionlib.io.asf_amc import read_amc, read_asf
from motionlib.io.bvh import check_bvh, read_bvh, write_bvh
from motionlib.io.c3dfile import read_c3d, write_c3d
from motionlib.io.pointcsv import read_points_csv, write_points_csv
from motionlib.io.qualisys import read_qualisys_tsv
from motionlib.take import DEFAULT_LIMITS, Limits, Take

__all__ = ["check_bvh", "read", "read_amc", "read_asf", "read_bvh", "read_c3d",
           "read_points_csv", "read_qualisys_tsv", "write_bvh", "write_c3d", "write_points_csv"]

POINT_READERS = {".c3d": read_c3d, ".tsv": read_qualisys_tsv, ".csv": read_points_csv}


def read(path: str | os.PathLike, *, asf: str | os.PathLike | None = None,
         limits: Limits = DEFAULT_LIMITS, animation: str | int | None = None) -> Take:
    """Read a capture: BVH by its ``.bvh`` extension, CMU ``.amc`` with its ``asf`` skeleton,
    FBX by ``.fbx`` (Blender reads it in a child process; see :mod:`motionlib.io.fbx`); a
    point take (:class:`motionlib.points.PointTake`) from C3D ``.c3d``, Qualisys ``.tsv`` or
    joint-position ``.csv`` (:mod:`motionlib.io.pointcsv`).

    Parameters
    ----------
    path : str or PathLike
    asf : str or PathLike, optional
        Required for ``.amc``.
    limits : Limits, optional
        What the file may hold and expand to (joints, frames, sizes, physical values).
    animation : str or int, optional
        For an FBX file with several animations: which one (name or 0-based number); the first
        by default.

    Returns
    -------
    Take

    Raises
    ------
    CaptureError
        Unknown extension, missing file, missing ``asf``, or any problem inside the files
        (the message names the file and line).
    """
    path = os.fspath(path)
    suffix = Path(path).suffix.lower()
    if suffix not in (".bvh", ".amc", ".fbx", *POINT_READERS):
        raise CaptureError(f"unknown capture format {suffix or '(no extension)'!r}; "
                           "expected .bvh, .fbx, .amc with its .asf, or points in .c3d, "
                           ".tsv (Qualisys) or .csv", path=path)
    for p in (path, asf):
        if p is not None and not Path(p).is_file():
            raise CaptureError("no such file", path=p)
    if suffix == ".bvh":
        return read_bvh(path, limits=limits)
    if suffix in POINT_READERS:
        return POINT_READERS[suffix](path, limits=limits)
    if suffix == ".fbx":
        from motionlib.io.fbx import read_fbx  # starts Blender only when an FBX is read

        return read_fbx(path, animation=animation, limits=limits)
    if asf is None:
        raise CaptureError("an .amc motion needs its .asf skeleton (pass the .asf file too)", path=path)
    return read_amc(path, asf, limits=limits)
