"""FBX: upload -> candidates through the convert worker, against the BVH of the same take, and
FBX / glTF export of a 10 s clip.

Everything runs as `make up` runs it: a temporary SQLite database, the SQLite broker, a
Celery worker for ingest and detection and a convert worker (Blender, loaded once as the
worker starts: its start-up is measured apart and not paid per file). Each repeat uploads
CMU 13_29 as the FBX Blender wrote (``../shared/data/fbx/13_29_blender.fbx``) and as the BVH
it came from (``../shared/data/cmu/bvh/13_29.bvh``), each into a project of its own (the same
file twice in one project is a duplicate), through the HTTP API (Django's test client), and
polls the database until the default detection run is ready.

Exports: frames [1200, 2400) of 13_29 (10 s at 120 fps), cut from the original FBX (same
armature), and written from the BVH take as a new armature, as FBX and as glTF binary, by a
Blender process already started (the web process keeps one, as the convert worker does).

    .venv/bin/python -m benchmarks fbx -- [--repeats 3] [--data ../shared/data]
"""

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.harness import REPO, data_dir
from benchmarks.harness.service import start_django, stop

DEFAULT_DATA = data_dir()


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA)
    return parser.parse_args()


def start_worker(var, name, *args, env=None):
    log_path = var / f"{name}.log"
    proc = subprocess.Popen(
        [str(Path(sys.executable).with_name("celery")), "-A", "cutroom", "worker",
         "--concurrency", "1", "--loglevel", "INFO", "--without-mingle", "--without-gossip",
         "--hostname", f"{name}@%h", *args],
        cwd=REPO, env={**os.environ, **(env or {})}, stdout=log_path.open("w"),
        stderr=subprocess.STDOUT, start_new_session=True,
    )
    proc.log_path = log_path
    return proc


def wait_for_line(proc, text, timeout=180):
    started = time.monotonic()
    while text not in proc.log_path.read_text():
        if proc.poll() is not None or time.monotonic() - started > timeout:
            sys.exit(f"{proc.log_path.name}: no {text!r}:\n{proc.log_path.read_text()[-3000:]}")
        time.sleep(0.05)
    return time.monotonic() - started


def upload_and_wait(client, project, path, timeout=300):
    """Seconds from the POST to converted (FBX only) and to a ready detection run."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation.models import Capture, DetectionRun

    start = time.time()
    response = client.post("/api/captures/", {
        "project": project.pk, "file": SimpleUploadedFile(path.name, path.read_bytes())},
        format="multipart")
    if response.status_code != 201:
        sys.exit(f"upload refused: {response.status_code} {response.content[:300]!r}")
    capture_id, converted = response.json()["id"], None
    while time.time() - start < timeout:
        capture = Capture.objects.only("status", "error", "converted").get(pk=capture_id)
        if capture.status == "failed":
            sys.exit(f"{path.name}: {capture.error}")
        if converted is None and capture.converted:
            converted = time.time() - start
        run = DetectionRun.objects.filter(capture_id=capture_id).only("status").first()
        if run is not None and run.status in ("ready", "failed"):
            break
        time.sleep(0.01)
    else:
        sys.exit(f"{path.name}: no candidates after {timeout} s")
    total = time.time() - start
    run = DetectionRun.objects.get(pk=run.pk)
    capture = Capture.objects.get(pk=capture_id)
    return {"total": total, "converted": converted, "cuts": len(run.candidates),
            "frames": capture.n_frames}


def service_rows(args):
    from django.contrib.auth import get_user_model
    from rest_framework.test import APIClient

    from segmentation import services

    user = get_user_model().objects.create_user("bench", password="bench-password")
    client = APIClient()
    client.force_authenticate(user)
    fbx = args.data / "fbx" / "13_29_blender.fbx"
    bvh = args.data / "cmu" / "bvh" / "13_29.bvh"
    rows = []
    for repeat in range(args.repeats):
        for path in (fbx, bvh):
            project = services.do_create_project(user, f"{path.name} {repeat}")
            rows.append({"repeat": repeat, "file": path.name,
                         **upload_and_wait(client, project, path)})
    return rows


def export_rows(args, repeats):
    import motionlib
    from motionlib.io.blender import Blender
    from motionlib.io.export import write_clip

    fbx = args.data / "fbx" / "13_29_blender.fbx"
    fbx_take = motionlib.read(fbx)
    bvh_take = motionlib.read(args.data / "cmu" / "bvh" / "13_29.bvh")
    blender = Blender()
    started = time.perf_counter()
    blender.start()
    startup = time.perf_counter() - started
    cases = [("FBX take -> FBX (cut from original)", fbx_take, "fbx", fbx),
             ("FBX take -> glTF (cut from original)", fbx_take, "glb", fbx),
             ("BVH take -> FBX (new armature)", bvh_take, "fbx", None),
             ("BVH take -> glTF (new armature)", bvh_take, "glb", None)]
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, take, fmt, original in cases:
            times, size = [], 0
            for _ in range(repeats):
                out = Path(folder) / f"clip.{fmt}"
                t = time.perf_counter()
                write_clip(take, out, format=fmt, start=1200, stop=2400, original=original,
                           blender=blender)
                times.append(time.perf_counter() - t)
                size = out.stat().st_size
            rows.append((name, times, size))
    blender.stop()
    return startup, rows


def report(args, startup_worker, rows, startup, exports):
    print(f"FBX benchmark; machine: {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f}; {args.repeats} repeats")
    print(f"convert worker: Blender loaded {startup_worker:.2f} s after the worker started "
          "(once per worker process, not per file)")
    print()
    print("upload -> candidates, embedded default (SQLite + SQLite broker, 1 ingest worker "
          "+ 1 convert worker), CMU 13_29")
    print(f"{'repeat':>6} {'file':<20} {'frames':>6} {'converted s':>11} {'total s':>8} "
          f"{'cuts':>5}")
    for row in rows:
        converted = "-" if row["converted"] is None else f"{row['converted']:.3f}"
        print(f"{row['repeat']:>6} {row['file']:<20} {row['frames']:>6} {converted:>11} "
              f"{row['total']:>8.3f} {row['cuts']:>5}")
    for name in sorted({r["file"] for r in rows}):
        totals = np.array([r["total"] for r in rows if r["file"] == name])
        print(f"  {name}: median {np.median(totals):.3f} s, max {totals.max():.3f} s")
    fbx = np.median([r["total"] for r in rows if r["file"].endswith(".fbx")])
    bvh = np.median([r["total"] for r in rows if r["file"].endswith(".bvh")])
    print(f"  FBX / BVH: {fbx / bvh:.2f}x (median); the difference is Blender reading the file")
    print()
    print(f"export of a 10 s clip (frames 1200-2400 of 13_29, 120 fps); Blender start-up "
          f"{startup:.2f} s paid once before these")
    print(f"{'case':<40} {'median s':>8} {'max s':>7} {'size MB':>8}")
    for name, times, size in exports:
        print(f"{name:<40} {np.median(times):>8.3f} {max(times):>7.3f} {size / 2**20:>8.2f}")


def main():
    args = parse_args()
    if not (args.data / "fbx" / "13_29_blender.fbx").is_file():
        sys.exit(f"no {args.data / 'fbx' / '13_29_blender.fbx'} (pass --data)")
    var = Path(tempfile.mkdtemp(prefix="cutroom-bench-fbx-"))
    workers = []
    try:
        start_django(unset=("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT",
                            "CELERY_BROKER_DIR", "CUTROOM_CONVERT_QUEUE"),
                     CUTROOM_VAR_DIR=str(var))
        workers.append(start_worker(var, "ingest"))
        workers.append(start_worker(var, "convert", "--queues", "convert",
                                    env={"CUTROOM_CONVERT_WORKER": "1"}))
        wait_for_line(workers[0], " ready.")
        startup_worker = wait_for_line(workers[1], "Blender ready in")
        rows = service_rows(args)
        startup, exports = export_rows(args, args.repeats)
        report(args, startup_worker, rows, startup, exports)
    finally:
        for worker in workers:
            stop(worker)
        shutil.rmtree(var, ignore_errors=True)

