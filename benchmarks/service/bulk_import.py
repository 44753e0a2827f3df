"""Bulk import: a folder of five-minute takes through ``manage.py import_captures``, with
one worker and with two.

Production setup on one machine: a scratch PostgreSQL database, Redis as the broker (db
``--redis-db``, a queue of this run's own), and N Celery workers (separate processes,
concurrency 1 each). The takes are seeded ``motionlib.synth`` takes of ``--minutes`` at
120 fps written as BVH, cached in ``benchmarks/out/`` (written once). For each worker
count the clock starts when ``import_captures`` starts (it checks and stores each file,
then queues it) and stops when every capture's default detection run is ready.

Each worker count runs for each ``--checks`` mode of the command: ``full`` (every frame
read before storing, what the command did before: the old path), ``header`` (the
default now: the hierarchy and motion header only) and ``none`` (``--no-check``).

Prints per mode and worker count: takes, hours of motion, wall time, hours of motion per
minute (per worker and in total), and the speed-up over one worker.

    DATABASE_ADMIN_URL=postgres://postgres@127.0.0.1:5432/postgres \\
        .venv/bin/python -m benchmarks bulk-import -- [--takes 1000] [--minutes 5] [--workers 1 2]
        [--checks full header]
"""

import argparse
import io
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.harness import PACKAGE, REPO
from benchmarks.harness.service import (
    drop_database,
    scratch_database,
    start_django,
    stop,
    up_script,
)

# The workers run as `make up` runs them: one core per pool process, no BLAS threads.
SINGLE_THREADED = up_script().SINGLE_THREADED

# This checkout's cache, also when the product under test is another revision's.
OUT = PACKAGE / "out"


def take_files(n, minutes, fps=120.0, seed=1000):
    """Paths of ``n`` cached synthetic takes (the missing ones written now)."""
    from motionlib import synth, write_bvh

    folder = OUT / f"bulk_{minutes:g}min_s{seed}"
    folder.mkdir(parents=True, exist_ok=True)
    paths = []
    for i in range(n):
        path = folder / f"take_{i:04d}.bvh"
        if not path.exists():
            take, _ = synth.generate(seed=seed + i, fps=fps, duration=minutes * 60)
            text = io.StringIO()
            write_bvh(take, text)
            path.with_suffix(".tmp").write_text(text.getvalue())
            path.with_suffix(".tmp").rename(path)
        paths.append(path)
    return folder, paths


CHECK_FLAGS = {"header": [], "full": ["--full-check"], "none": ["--no-check"]}


def run(n_workers, folder, paths, env, var, check="header"):
    """Seconds from the command's start to the last ready run."""
    from django.contrib.auth import get_user_model

    from segmentation import services
    from segmentation.models import DetectionRun

    user = get_user_model().objects.create_user(f"importer{n_workers}{check}")
    project = services.do_create_project(user, f"Bulk {n_workers} {check}")
    workers = [start_worker(env, var, f"bulk{n_workers}{check}_{i}") for i in range(n_workers)]
    try:
        started = time.perf_counter()
        command = subprocess.run(
            [sys.executable, "manage.py", "import_captures", str(folder), "--project",
             str(project.pk), "--user", user.username, *CHECK_FLAGS[check]],
            cwd=REPO, env=env,
            capture_output=True, text=True)
        imported = time.perf_counter() - started
        if command.returncode or f" {len(paths)} imported," not in command.stdout:
            raise SystemExit(f"import_captures failed:\n{command.stdout[-2000:]}\n{command.stderr[-2000:]}")
        runs = DetectionRun.objects.filter(capture__project=project)
        while runs.filter(status="ready").count() < len(paths):
            if runs.filter(status="failed").exists() or time.perf_counter() - started > 7200:
                raise SystemExit(f"runs failed or timed out: {list(runs.values('status', 'error'))[:3]}")
            time.sleep(0.2)
        return imported, time.perf_counter() - started, sum(cpu_seconds(w.pid) for w in workers)
    finally:
        for worker in workers:
            stop(worker)


def cpu_seconds(pid):
    """User + system CPU seconds of a process and its children (the worker's pool)."""
    tick = os.sysconf("SC_CLK_TCK")
    total = 0.0
    kids = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout.split()
    for p in [pid, *map(int, kids)]:
        try:
            fields = Path(f"/proc/{p}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        total += (int(fields[11]) + int(fields[12])) / tick
    return total


def start_worker(env, var, name):
    log = var / f"{name}.log"
    proc = subprocess.Popen(
        [str(Path(sys.executable).with_name("celery")), "-A", "cutroom", "worker", "--concurrency",
         "1", "--loglevel", "INFO", "--without-mingle", "--without-gossip", "-n", f"{name}@%h"],
        cwd=REPO, env={**SINGLE_THREADED, **env}, stdout=log.open("w"), stderr=subprocess.STDOUT,
        start_new_session=True)
    deadline = time.monotonic() + 60
    while " ready." not in log.read_text():
        if proc.poll() is not None or time.monotonic() > deadline:
            raise SystemExit(f"worker did not start:\n{log.read_text()}")
        time.sleep(0.1)
    return proc


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--takes", type=int, default=1000)
    parser.add_argument("--minutes", type=float, default=5.0)
    parser.add_argument("--workers", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--checks", nargs="+", choices=sorted(CHECK_FLAGS), default=["full", "header"],
                        help="how import_captures checks files: full (--full-check, every frame "
                             "read before storing: what it did before), header (the default: "
                             "hierarchy and motion header), none (--no-check)")
    parser.add_argument("--redis-db", type=int, default=int(os.environ.get("BENCH_REDIS_DB", 8)))
    parser.add_argument("--admin-url", default=os.environ.get(
        "DATABASE_ADMIN_URL", "postgres://postgres@127.0.0.1:5432/postgres"))
    args = parser.parse_args()
    started = time.perf_counter()
    folder, paths = take_files(args.takes, args.minutes)
    prepared = time.perf_counter() - started
    name = f"cutroom_bench_bulk_{os.getpid()}"
    var = Path(tempfile.mkdtemp(prefix="cutroom-bulk-"))
    url = scratch_database(args.admin_url, name)
    env = {**os.environ, "DATABASE_URL": url, "CUTROOM_MEDIA_ROOT": str(var / "media"),
           "CELERY_BROKER_URL": f"redis://127.0.0.1:6379/{args.redis_db}",
           "CELERY_QUEUE": name, "CUTROOM_VAR_DIR": str(var),
           # An archive is imported by an operator: no hourly upload limit (120 by default).
           "CUTROOM_UPLOADS_PER_HOUR": "0"}
    hours = args.takes * args.minutes / 60
    try:
        start_django(**{k: env[k] for k in ("DATABASE_URL", "CUTROOM_MEDIA_ROOT",
                                            "CELERY_BROKER_URL", "CELERY_QUEUE", "CUTROOM_VAR_DIR")})
        print(f"bulk import: {args.takes} synthetic takes of {args.minutes:g} min at 120 fps"
              f" ({hours:.1f} h of motion, {sum(p.stat().st_size for p in paths) / 2**30:.1f} GB BVH, "
              f"{'written' if prepared > 1 else 'cached'} in {prepared:.0f} s); PostgreSQL + Redis, "
              f"workers of concurrency 1; machine: {os.cpu_count()} cores shared with other work, "
              f"load {os.getloadavg()[0]:.1f}\n", flush=True)
        header = (f"{'check':>6} {'workers':>7} {'takes':>6} {'command s':>10} {'total s':>9} "
                  f"{'h motion/min':>13} {'per worker':>11} {'speed-up':>9} {'worker CPU s':>13} "
                  f"{'CPU s/take':>11}")
        print(header)
        print("-" * len(header), flush=True)
        for check in args.checks:
            one = None
            for n in args.workers:
                imported, total, cpu = run(n, folder, paths, env, var, check=check)
                rate = hours / (total / 60)
                one = one or rate
                print(f"{check:>6} {n:>7} {args.takes:>6} {imported:>10.1f} {total:>9.1f} "
                      f"{rate:>13.2f} {rate / n:>11.2f} {rate / one:>8.2f}x {cpu:>13.1f} "
                      f"{cpu / args.takes:>11.2f}", flush=True)
        print(f"\nload at the end {os.getloadavg()[0]:.1f}. (command s: import_captures itself, "
              "which checks, stores and queues each file; "
              "total s: until the last detection run is ready; worker CPU s: user + system time of "
              "the workers and their pool processes, which says what the work costs whatever the "
              "machine's load)")
    finally:
        from django.db import connections

        connections.close_all()
        drop_database(args.admin_url, name)
        shutil.rmtree(var, ignore_errors=True)

