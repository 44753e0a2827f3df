"""How long hostile capture files take to read or refuse, and how much memory they cost.

    .venv/bin/python -m benchmarks hostile-inputs

The files are generated in a temporary folder: flat and nested hierarchies of 10,000 to
80,000 joints (read with the joint limit raised, to show the time grows linearly with the
size; at the default limit of 1,000 they are refused), a ``Frames: 10^12`` header, and the
639 KB file of 1,000 channel-less joints x 50,000 frames. Each case is read once after a
warm-up; the table gives wall and CPU milliseconds (the CPU time is what other jobs lose),
and the peak memory traced in one more read.
"""

from __future__ import annotations

import os
import tempfile
import time
import tracemalloc
from pathlib import Path

import motionlib
from motionlib.take import DEFAULT_LIMITS, Limits

HEAD = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Yposition\n"
TAIL = "MOTION\nFrames: {n}\nFrame Time: 0.01\n"


def flat(n_children: int, n_frames: int = 2) -> str:
    joints = "".join(f"  JOINT j{i}\n  {{\n    OFFSET 0 1 0\n  }}\n" for i in range(n_children))
    return HEAD + joints + "}\n" + TAIL.format(n=n_frames) + "0\n" * n_frames


def nested(depth: int, n_frames: int = 2) -> str:
    opening = "".join(f"JOINT j{i}\n{{\nOFFSET 0 1 0\n" for i in range(depth))
    return (HEAD + opening + "}\n" * (depth + 1) + TAIL.format(n=n_frames) + "0\n" * n_frames)


def cases():
    wide = Limits(max_joints=100_000, max_joint_frames=10**9, max_expansion=10**6)
    for n in (10_000, 20_000, 40_000, 80_000):
        yield f"flat, {n} joints (limit raised)", flat(n), wide
    for n in (20_000, 80_000):
        yield f"nested {n} deep (limit raised)", nested(n), wide
    yield "flat, 80,000 joints", flat(80_000), DEFAULT_LIMITS
    yield "nested 80,000 deep", nested(80_000), DEFAULT_LIMITS
    yield "Frames: 10^12", flat(1, 1).replace("Frames: 1", "Frames: 1000000000000"), DEFAULT_LIMITS
    yield "1,000 joints x 50,000 frames", flat(999, 50_000), DEFAULT_LIMITS


def read(path: Path, limits: Limits) -> str:
    try:
        return f"read: {motionlib.read(path, limits=limits).skeleton.n_joints} joints"
    except motionlib.CaptureError as exc:
        return "refused: " + exc.reason[:60]


def measure(path: Path, limits: Limits) -> tuple[str, float, float, float]:
    """(outcome, wall ms, CPU ms, peak traced MB); memory is traced in a separate read, since
    tracing slows Python code down several times."""
    read(path, limits)  # warm-up
    wall, cpu = time.perf_counter(), time.process_time()
    outcome = read(path, limits)
    wall, cpu = (time.perf_counter() - wall) * 1e3, (time.process_time() - cpu) * 1e3
    tracemalloc.start()
    read(path, limits)
    peak = tracemalloc.get_traced_memory()[1] / 2**20
    tracemalloc.stop()
    return outcome, wall, cpu, peak


def main() -> None:
    print(f"hostile capture files, one read each after a warm-up; load average "
          f"{os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"{'case':<34} {'file':>9} {'wall ms':>8} {'CPU ms':>8} {'peak MB':>8}  outcome")
    with tempfile.TemporaryDirectory() as folder:
        for name, text, limits in cases():
            path = Path(folder) / "case.bvh"
            path.write_text(text)
            outcome, wall, cpu, peak = measure(path, limits)
            size = f"{path.stat().st_size / 1024:.0f} KB"
            print(f"{name:<34} {size:>9} {wall:>8.1f} {cpu:>8.1f} {peak:>8.1f}  {outcome}")

