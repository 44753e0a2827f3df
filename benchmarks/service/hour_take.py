"""An hour-long take end to end: upload -> candidates, the review page's first pose,
whole signal and every pose, and the worker's peak memory.

Runs as ``make up`` does (a temporary SQLite database, the SQLite broker, one Celery
worker subprocess with concurrency 1). The take is a seeded ``motionlib.synth`` take of
``--minutes`` (default 60) at 120 fps written as BVH, cached in ``benchmarks/out/``. It is
uploaded through the HTTP API (Django's test client) with the shipped limits, the clock stops when the default detection run is ready. Then, as the
review page does: the capture, the first 600 poses (``frames/?start=0&stop=600``), the
overview signal (4,000 points), the whole signal (one value per frame), and every pose:
as the page asked for them before (JSON chunks of at most 5,000 frames, one after another)
and as it asks now (the rest after the first 600 as one streamed float32 answer,
``/poses/``; "(none)" on a revision without it). In-process, so no socket or browser time:
``review-poses`` times the page in Chromium.

The worker's memory is sampled every 50 ms (resident set of the worker and its pool
process, from ``/proc``); the peak of the pool process (the one that runs the job) and of
both together are printed, with the kernel's own high-water mark (VmHWM) of each.

    .venv/bin/python -m benchmarks hour-take -- [--minutes 60]
"""

import argparse
import io
import os
import shutil
import tempfile
import threading
import time
from pathlib import Path

from benchmarks.harness import PACKAGE
from benchmarks.harness.service import stop
from benchmarks.service.upload_to_candidates import (
    client_and_project,
    embedded_environment,
    start_worker,
    upload_and_wait,
)

# This checkout's cache, also when the product under test is another revision's.
OUT = PACKAGE / "out"
TARGETS = {"upload -> candidates": 5.0, "first pose": 0.5, "whole signal": 2.0}


def take_file(minutes, fps, seed=60):
    """The cached BVH of a seeded synthetic take (written once)."""
    path = OUT / f"hour_take_{minutes:g}min_{fps:g}fps_s{seed}.bvh"
    if not path.exists():
        from motionlib import synth, write_bvh

        OUT.mkdir(parents=True, exist_ok=True)
        take, _ = synth.generate(seed=seed, fps=fps, duration=minutes * 60)
        text = io.StringIO()
        write_bvh(take, text)
        tmp = path.with_suffix(".tmp")
        tmp.write_text(text.getvalue())
        tmp.rename(path)
    return path


def _status(pid, field):
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1])  # kB
    except OSError:
        pass
    return 0


def _children(pid):
    found = []
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            found += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            pass
    return found


class MemoryWatch(threading.Thread):
    """Peak resident memory (kB) of a process and its children, sampled every 50 ms."""

    def __init__(self, pid):
        super().__init__(daemon=True)
        self.pid, self.peak_total, self.peak_child, self.hwm = pid, 0, 0, {}
        self.running = True

    def run(self):
        while self.running:
            kids = _children(self.pid)
            sizes = {p: _status(p, "VmRSS") for p in [self.pid, *kids]}
            self.peak_total = max(self.peak_total, sum(sizes.values()))
            self.peak_child = max([self.peak_child, *(sizes[k] for k in kids)])
            for p in sizes:
                self.hwm[p] = max(self.hwm.get(p, 0), _status(p, "VmHWM"))
            time.sleep(0.05)


def timed_get(client, url):
    """(seconds, bytes) of one GET, its body read whole (streamed or not); None for a
    path this revision does not have (404)."""
    started = time.perf_counter()
    response = client.get(url)
    body = b"".join(response.streaming_content) if response.streaming else response.content
    elapsed = time.perf_counter() - started
    if response.status_code == 404:
        return None
    if response.status_code != 200:
        raise SystemExit(f"{url}: HTTP {response.status_code} {body[:300]!r}")
    return elapsed, len(body)


def every_pose_as_json(client, capture):
    """(seconds, bytes) of every pose through /frames/ as the page asked before: chunks of
    at most 5,000 frames, each continuing from the last answer's ``stop``."""
    started, size, start = time.perf_counter(), 0, 0
    while start < capture.n_frames:
        response = client.get(f"/api/captures/{capture.pk}/frames/?start={start}&step=1")
        size += len(response.content)
        start = response.json()["stop"]
    return time.perf_counter() - started, size


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0)
    parser.add_argument("--fps", type=float, default=120.0)
    args = parser.parse_args()
    started = time.perf_counter()
    path = take_file(args.minutes, args.fps)
    prepared = time.perf_counter() - started
    var = Path(tempfile.mkdtemp(prefix="cutroom-hour-"))
    worker = watch = None
    try:
        embedded_environment(var)
        client, project = client_and_project()
        worker = start_worker(var)
        watch = MemoryWatch(worker.pid)
        watch.start()
        content = path.read_bytes()
        row = upload_and_wait(client, project, path.name, content, timeout=1800)
        from segmentation.models import Capture

        capture = Capture.objects.latest("id")
        del content
        pages = [
            ("capture", f"/api/captures/{capture.pk}/"),
            ("first pose (600 frames)", f"/api/captures/{capture.pk}/frames/?start=0&stop=600&step=1"),
            ("overview signal (4000 points)", f"/api/captures/{capture.pk}/signal/?max_points=4000"),
            ("whole signal, JSON (before)", f"/api/captures/{capture.pk}/signal/?max_points={capture.n_frames}"),
            ("whole signal, float32 (page)",
             f"/api/captures/{capture.pk}/signal/?max_points={capture.n_frames}&encoding=float32"),
        ]
        times = {title: timed_get(client, url) for title, url in pages}
        times["every pose, JSON chunks (before)"] = every_pose_as_json(client, capture)
        times["every pose, one float32 stream"] = timed_get(
            client, f"/api/captures/{capture.pk}/poses/?start=600")
        watch.running = False
        watch.join()
        print(f"hour-long take: {capture.n_frames:,} frames at {capture.fps:g} fps "
              f"({capture.n_frames / capture.fps / 60:.0f} min), {path.stat().st_size / 2**20:.0f} MB "
              f"BVH ({'written' if prepared > 1 else 'cached'} in {prepared:.0f} s); embedded default "
              f"(SQLite, SQLite broker, 1 worker, concurrency 1); machine: {os.cpu_count()} cores "
              f"shared with other work, load {os.getloadavg()[0]:.1f}\n")
        print(f"{'step (as the run rows stamp them)':<32} {'seconds':>8} {'target':>7}")
        print("-" * 49)
        stages = [("POST (upload + store)", row["post"]),
                  ("ingest (queue, parse, FK, store)", row["ingest"]),
                  ("detect (run + store)", row["detect"]), ("  of which the segmenter", row["segmenter"]),
                  ("upload -> candidates", row["total"])]
        for title, seconds in stages:
            target = TARGETS.get(title)
            print(f"{title:<32} {seconds:>8.2f} {target if target else '':>7}")
        first = times["capture"][0] + times["first pose (600 frames)"][0]
        for title, answer in times.items():
            if answer is None:
                print(f"{title:<32} {'(none)':>8} {'':>7}  (this revision has no such path)")
                continue
            seconds, size = answer
            print(f"{title:<32} {seconds:>8.2f} {'':>7}  ({size / 2**20:.1f} MB)")
        print(f"{'first pose (capture + frames)':<32} {first:>8.2f} {TARGETS['first pose']:>7}")
        print(f"{'whole signal (as the page asks)':<32} {times['whole signal, float32 (page)'][0]:>8.2f} "
              f"{TARGETS['whole signal']:>7}")
        print(f"\nworker memory: pool process peak {watch.peak_child / 2**20:.2f} GB, worker + pool "
              f"peak {watch.peak_total / 2**20:.2f} GB (target 2 GB); VmHWM per process: "
              + ", ".join(f"{v / 2**20:.2f} GB" for v in watch.hwm.values()))
        print(f"{row['cuts']} candidate cuts")
    finally:
        if watch is not None:
            watch.running = False
        if worker is not None:
            stop(worker)
        shutil.rmtree(var, ignore_errors=True)

