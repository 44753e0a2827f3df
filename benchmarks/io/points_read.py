"""Point-take reading: the HDM05 Vicon C3D against a BVH of the same number of values, the
independent C3D readers on the same file, and a trimmed C3D export opened by ezc3d.

- ``motionlib C3D``: ``motionlib.read`` of ``points/hdm05/HDM_bd_05-01_01_120.c3d`` (44
  markers x 5,920 frames x 3 = 781,440 values), everything a reader returns (points Y up,
  gaps, marker set).
- ``motionlib BVH``: ``motionlib.read`` of a BVH holding the same number of values: CMU 13_29's
  96 channels with its frames repeated to 8,140 frames (written to a temporary file first).
- ``ezc3d`` and ``c3d package``: the two C3D readers on PyPI, on the same file (the c3d
  package frame by frame, as it reads).
- The coordinates motionlib reads are compared with ezc3d's frame by frame; the clip of frames
  [1200, 2400) written by ``write_c3d`` is opened by ezc3d and its markers, frames, rate and
  coordinates compared with the take's.
- The Qualisys TSV and joint-position CSV takes are timed for the record (values per second).

Times are the best and the median of ``--repeats`` reads, the readers interleaved.

    .venv/bin/python -m benchmarks points-read -- [--repeats 15] [--data ../shared/data]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

import motionlib
from benchmarks.harness import data_dir
from motionlib.io.c3dfile import write_c3d

DEFAULT_DATA = data_dir()
HDM05 = Path("points/hdm05/HDM_bd_05-01_01_120.c3d")


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    return parser.parse_args()


def bvh_of(n_values: int, bvh: Path, out: Path) -> Path:
    """A BVH with ``n_values`` channel values (rounded up to whole frames) from ``bvh``'s."""
    take = motionlib.read(bvh)
    n_frames = -(-n_values // take.skeleton.n_channels)
    reps = -(-n_frames // take.n_frames)
    channels = np.tile(take.channels, (reps, 1))[:n_frames]
    motionlib.write_bvh(replace(take, channels=channels), out)
    return out


def ezc3d_read(path):
    import ezc3d

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return ezc3d.c3d(str(path))


def c3d_package_read(path):
    import c3d

    with warnings.catch_warnings(), open(path, "rb") as handle:
        warnings.simplefilter("ignore")
        return np.stack([p for _, p, _ in c3d.Reader(handle).read_frames()])


def timed(readers: dict, repeats: int) -> dict[str, list[float]]:
    times = {name: [] for name in readers}
    for _ in range(repeats):
        for name, read in readers.items():
            start = time.perf_counter()
            read()
            times[name].append(time.perf_counter() - start)
    return times


def check_against_ezc3d(take, path) -> float:
    other = ezc3d_read(path)["data"]["points"][:3]
    xyz = np.moveaxis(other, [0, 1, 2], [2, 1, 0]).reshape(take.n_frames, -1)
    both = ~np.isnan(xyz) & ~np.isnan(take.channels)
    if not np.array_equal(np.isnan(xyz), np.isnan(take.channels)):
        return float("inf")
    return float(np.abs(xyz[both] - take.channels[both]).max())


def check_export(take, scratch: Path) -> str:
    path = scratch / "clip.c3d"
    write_c3d(take, path, start=1200, stop=2400)
    other = ezc3d_read(path)
    labels = other["parameters"]["POINT"]["LABELS"]["value"]
    rate = float(other["parameters"]["POINT"]["RATE"]["value"][0])
    xyz = np.moveaxis(other["data"]["points"][:3], [0, 1, 2], [2, 1, 0])
    same = np.array_equal(xyz.reshape(xyz.shape[0], -1), take.channels[1200:2400],
                          equal_nan=True)
    return (f"ezc3d opens the clip [1200, 2400): {len(labels)} markers "
            f"({'same' if labels == take.point_names else 'DIFFERENT'} labels), "
            f"{xyz.shape[0]} frames, {rate:g} Hz, first frame "
            f"{other['header']['points']['first_frame'] + 1}, coordinates "
            f"{'equal' if same else 'DIFFERENT'}")


def main():
    args = parse_args()
    c3d_path = args.data / HDM05
    if not c3d_path.is_file():
        sys.exit(f"{c3d_path} not found (needs ../shared/data/points)")
    take = motionlib.read(c3d_path)
    n_values = take.channels.size
    with tempfile.TemporaryDirectory() as scratch:
        scratch = Path(scratch)
        bvh = bvh_of(n_values, args.data / "cmu" / "bvh" / "13_29.bvh", scratch / "same.bvh")
        bvh_values = motionlib.read(bvh).channels.size
        tsv = args.data / "points" / "vmci" / "subject1_run4.tsv"
        csv = args.data / "points" / "utkinect" / "s04_e02.csv"
        readers = {
            "motionlib C3D": lambda: motionlib.read(c3d_path),
            "motionlib BVH": lambda: motionlib.read(bvh),
            "ezc3d": lambda: ezc3d_read(c3d_path),
            "c3d package": lambda: c3d_package_read(c3d_path),
            "motionlib TSV": lambda: motionlib.read(tsv),
            "motionlib CSV": lambda: motionlib.read(csv),
        }
        values = {"motionlib C3D": n_values, "motionlib BVH": bvh_values, "ezc3d": n_values,
                  "c3d package": n_values, "motionlib TSV": motionlib.read(tsv).channels.size,
                  "motionlib CSV": motionlib.read(csv).channels.size}
        times = timed(readers, args.repeats)
        export = check_export(take, scratch)
    print(f"Point-take reading, best / median of {args.repeats} reads")
    print(f"{'reader':<16}{'values':>10}{'best ms':>10}{'median ms':>11}{'Mvalues/s':>11}")
    for name, ts in times.items():
        best = min(ts)
        print(f"{name:<16}{values[name]:>10}{best * 1e3:>10.1f}{np.median(ts) * 1e3:>11.1f}"
              f"{values[name] / best / 1e6:>11.1f}")
    ratio = min(times["motionlib C3D"]) / min(times["motionlib BVH"])
    median_ratio = np.median(times["motionlib C3D"]) / np.median(times["motionlib BVH"])
    print(f"C3D / BVH read time for the same number of values: {ratio:.2f} (best), "
          f"{median_ratio:.2f} (median); target at most 3")
    print(f"largest difference from ezc3d's coordinates, frame by frame: "
          f"{check_against_ezc3d(take, c3d_path):g} mm")
    print(export)

