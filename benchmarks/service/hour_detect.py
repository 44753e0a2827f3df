"""Default detection of the hour-long take with and without the world positions ingest
has already computed (``Take.positions``), old and new alternately in one process.

The worker's ingest computes forward kinematics to store the positions and then runs the
default detection on the same take; before, detection computed them a second time. Uses
the cached take of ``hour_take.py`` (written when missing).

    .venv/bin/python -m benchmarks hour-detect -- [--minutes 60] [--repeats 2]
"""

import argparse
import os
import time

import numpy as np

from benchmarks.service.hour_take import take_file


def timed(function):
    wall, cpu = time.perf_counter(), time.process_time()
    result = function()
    return result, time.perf_counter() - wall, time.process_time() - cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    import motionlib
    from motionlib.segmenters import get_segmenter

    path = take_file(args.minutes, 120.0)
    take, read_s, _ = timed(lambda: motionlib.read(path))
    positions, fk_s, fk_cpu = timed(lambda: motionlib.forward_kinematics(take))
    positions.flags.writeable = False
    given = motionlib.Take(**{**take.__dict__, "positions": positions})
    print(f"hour-long take {path.name}: {take.n_frames:,} frames at {take.fps:g} fps; read "
          f"{read_s:.2f} s, forward kinematics {fk_s:.2f} s ({fk_cpu:.2f} s CPU); machine: "
          f"{os.cpu_count()} cores shared with other work, load "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}\n")
    print(f"{'path':<40} {'repeat':>6} {'wall s':>7} {'CPU s':>6} {'cuts':>5}")
    cuts = {}
    for repeat in range(args.repeats):
        for title, subject in (("old: detection computes positions again", take),
                               ("new: detection reuses ingest's", given)):
            result, wall, cpu = timed(lambda s=subject: get_segmenter("default")().fit_predict(s))
            cuts.setdefault(title, []).append(np.asarray(result.cuts))
            print(f"{title:<40} {repeat:>6} {wall:>7.2f} {cpu:>6.2f} {len(result.cuts):>5}")
    same = all(np.array_equal(a, b) for a, b in zip(*cuts.values(), strict=True))
    print(f"\nsame cuts on both paths: {same}; load after "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}")

