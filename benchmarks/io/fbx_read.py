"""Reading an FBX take against reading the BVH of the same take, Blender's read and the
service's read of the stored take in the same run.

CMU 13_29 as the FBX Blender wrote (``../shared/data/fbx/13_29_blender.fbx``) and as the BVH it
came from (``../shared/data/cmu/bvh/13_29.bvh``) are uploaded to a temporary installation on
the embedded default (SQLite), converted (FBX) and ingested by the service's own task
functions, in this process. Then each is read as the service reads a take for detection,
review, exports and previews (``segmentation.files.storage.read_take``), and the FBX is also read
the way it was read before the conversion kept its take: by Blender's importer, with Blender
already running (its start-up is paid once per process and stated apart). The take the
service reads back is checked equal to Blender's read.

    .venv/bin/python -m benchmarks fbx-read -- [--repeats 20] [--blender-repeats 5]
"""

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.harness import data_dir
from benchmarks.harness.service import start_django


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=20)
    parser.add_argument("--blender-repeats", type=int, default=5)
    parser.add_argument("--data", type=Path, default=data_dir())
    return parser.parse_args()


def timed(call, repeats):
    """Milliseconds of each of ``repeats`` calls after one untimed warm-up; the last result."""
    result, times = call(), []
    for _ in range(repeats):
        started = time.perf_counter()
        result = call()
        times.append((time.perf_counter() - started) * 1000)
    return times, result


def ingest(project, user, path):
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services, tasks
    from segmentation.models import Capture

    capture, _ = services.do_upload_capture(
        project, user, SimpleUploadedFile(path.name, path.read_bytes()))
    if capture.needs_conversion:
        tasks.convert(capture.pk)
    tasks.ingest(capture.pk)
    capture = Capture.objects.get(pk=capture.pk)
    if capture.status != "ready":
        sys.exit(f"{path.name}: {capture.status} {capture.error}")
    return capture


def main():
    args = parse_args()
    fbx = args.data / "fbx" / "13_29_blender.fbx"
    bvh = args.data / "cmu" / "bvh" / "13_29.bvh"
    for path in (fbx, bvh):
        if not path.is_file():
            sys.exit(f"no {path} (pass --data)")
    var = Path(tempfile.mkdtemp(prefix="cutroom-bench-fbx-read-"))
    try:
        start_django(unset=("DATABASE_URL", "CUTROOM_MEDIA_ROOT"), CUTROOM_VAR_DIR=str(var))
        rows, startup, same = measure(args, fbx, bvh)
    finally:
        shutil.rmtree(var, ignore_errors=True)
    report(args, rows, startup, same)


def measure(args, fbx, bvh):
    from django.contrib.auth import get_user_model

    import motionlib
    from motionlib.io import blender as blender_module
    from segmentation import services
    from segmentation.files.storage import read_take

    started = time.perf_counter()
    blender_module.shared().start()
    startup = time.perf_counter() - started
    user = get_user_model().objects.create_user("bench")
    fbx_capture = ingest(services.do_create_project(user, "FBX"), user, fbx)
    bvh_capture = ingest(services.do_create_project(user, "BVH"), user, bvh)
    cases = [
        ("OLD FBX: Blender reads the file", lambda: motionlib.read(fbx), args.blender_repeats),
        ("NEW FBX: the stored converted take", lambda: read_take(fbx_capture), args.repeats),
        ("BVH: the original parsed", lambda: read_take(bvh_capture), args.repeats),
    ]
    rows, takes = [], {}
    for name, call, repeats in cases:
        times, takes[name] = timed(call, repeats)
        rows.append((name, times, takes[name]))
    old, new = takes[cases[0][0]], takes[cases[1][0]]
    same = (np.array_equal(old.channels, new.channels) and old.skeleton.names == new.skeleton.names
            and np.array_equal(old.skeleton.offsets, new.skeleton.offsets))
    blender_module.shared().stop()
    return rows, startup, same


def report(args, rows, startup, same):
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    print(f"FBX read vs BVH read of CMU 13_29; machine: {os.cpu_count()} cores, load average "
          f"{load} at the end; embedded default (SQLite, local file storage)")
    print(f"Blender started once before the OLD reads: {startup:.2f} s (not counted below)")
    print()
    print(f"{'case':<38} {'runs':>4} {'median ms':>10} {'p95 ms':>8} {'frames':>6} {'x BVH':>7}")
    bvh_median = statistics.median(rows[-1][1])
    for name, times, take in rows:
        median = statistics.median(times)
        p95 = statistics.quantiles(times, n=20)[-1] if len(times) > 1 else times[0]
        print(f"{name:<38} {len(times):>4} {median:>10.1f} {p95:>8.1f} {take.n_frames:>6} "
              f"{median / bvh_median:>7.2f}")
    print()
    print(f"stored take equal to Blender's read (channels, joints, offsets): "
          f"{'yes' if same else 'NO'}")
    ratio = statistics.median(rows[1][1]) / bvh_median
    print(f"NEW FBX read / BVH read: {ratio:.2f}x (target <= 10x): "
          f"{'ok' if ratio <= 10 else 'MISSED'}")

