"""Capture list under load: ``GET /api/captures/`` on PostgreSQL with 10,000 captures.

A scratch database is created on the local PostgreSQL (and dropped afterwards), filled
with 10,000 ready captures (CMU-sized skeletons, one finished detection run each with
its candidates) spread over three projects of one user, plus a project of someone
else's; gunicorn serves the app on loopback and ``wrk`` (Debian's; a bounded Python
client if it is missing) requests the list with a token for a fixed time per scenario.
Queries and CPU time per request are measured in-process for the same URLs.

    .venv/bin/python -m benchmarks capture-list-load -- [--captures 10000] [--seconds 10]
        [--connections 4] [--workers 4] [--threads 1] [--postgres postgres://postgres@127.0.0.1:5432]

Target: p95 <= 100 ms.
"""

import argparse
import os
import random
import re
import shutil
import socket
import subprocess
import sys
import tempfile
import threading
import time
import urllib.request
from pathlib import Path

import numpy as np

from benchmarks.harness import REPO
from benchmarks.harness.service import drop_database, scratch_database, start_django, stop

TARGET_MS = 100.0
SCENARIOS = [
    ("first page", "/api/captures/"),
    ("middle page", "/api/captures/?page={middle}"),
    ("one project, ready", "/api/captures/?project={project}&status=ready"),
    ("search", "/api/captures/?search=walk"),
]
LUA = """
done = function(summary, latency, requests)
  local e = summary.errors
  io.write(string.format("RESULT %d %d %d %d %d %d\\n", latency:percentile(50),
    latency:percentile(95), latency:percentile(99), summary.requests, summary.duration,
    e.connect + e.read + e.write + e.timeout + e.status))
end
"""


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--captures", type=int, default=10_000)
    parser.add_argument("--seconds", type=float, default=10.0)
    parser.add_argument("--connections", type=int, default=4)
    parser.add_argument("--postgres", default="postgres://postgres@127.0.0.1:5432")
    parser.add_argument("--workers", type=int, default=4, help="gunicorn worker processes")
    parser.add_argument("--threads", type=int, default=1,
                        help="threads per gunicorn worker (1: sync workers, as in production)")
    return parser.parse_args()


def seed(n_captures):
    """Users, projects and ``n_captures`` ready captures with a finished run; returns
    (token key, id of the first project)."""
    from django.contrib.auth import get_user_model

    from accounts.models import ApiToken
    from segmentation import services

    users = get_user_model().objects
    owner, stranger = users.create_user("owner"), users.create_user("stranger")
    projects = [services.do_create_project(owner, f"Studio {i}") for i in range(3)]
    other = services.do_create_project(stranger, "Someone else's studio")
    rng = random.Random(0)
    share = [n_captures // 2, n_captures // 3, n_captures - n_captures // 2 - n_captures // 3]
    for project, count in zip(projects, share, strict=True):
        _captures(project, owner, count, rng)
    _captures(other, stranger, 1000, rng)
    from django.db import connection

    with connection.cursor() as cursor:
        # What autovacuum does soon after a bulk load: planner statistics, visibility map.
        cursor.execute("VACUUM ANALYZE")
    return ApiToken.objects.issue(owner)[1], projects[0].pk


def _captures(project, user, count, rng):
    from datetime import timedelta

    from django.utils import timezone

    from segmentation.models import Capture, DetectionRun

    skeleton = {"joints": [f"joint{j}" for j in range(31)], "parents": [-1] + list(range(30)),
                "height": 17.7, "up": "y"}
    actions = ["walk", "run", "punch", "squat", "kick", "jumping_jack"]
    now = timezone.now()
    rows = []
    for i in range(count):
        n_frames = rng.randrange(1200, 40_000)
        rows.append(Capture(
            project=project, uploaded_by=user, status="ready", format="bvh", fps=120.0,
            name=f"{rng.choice(actions)}_{project.pk}_{i:05d}.bvh", checksum=f"{project.pk}-{i}",
            original=f"captures/{project.pk}/{i}/take.bvh", n_frames=n_frames, n_joints=31,
            skeleton=skeleton, positions=f"derived/{project.pk}/{i}/positions.npy",
            created_at=now - timedelta(seconds=count - i),
        ))
    captures = Capture.objects.bulk_create(rows, batch_size=2000)
    runs = []
    for capture in captures:
        frames = sorted(rng.sample(range(1, capture.n_frames), 30))
        runs.append(DetectionRun(
            capture=capture, method="default", params={"scales": [0.5, 1.0, 2.0]},
            status="ready", created_at=capture.created_at, finished_at=capture.created_at,
            candidates=[{"frame": f, "confidence": round(rng.random(), 4)} for f in frames],
            timings={"kinematics": 0.05, "novelty": 0.1, "cuts": 0.01, "total": 0.16},
            signals=f"derived/{capture.pk}/signals.npz",
        ))
    DetectionRun.objects.bulk_create(runs, batch_size=2000)


def in_process_cost(token_key, paths, repeats=20):
    """path -> (SQL queries per request, median CPU ms per request), measured in-process.

    CPU time of this process (view, serializers, JSON, the driver's side of the queries)
    depends far less on other load on the machine than wall-clock latency does.
    """
    from django.db import connection, reset_queries
    from django.test.utils import CaptureQueriesContext
    from rest_framework.test import APIClient

    client = APIClient()
    client.credentials(HTTP_AUTHORIZATION=f"Token {token_key}")
    costs = {}
    for path in paths:
        # Each request start empties the query log: count from an empty one.
        reset_queries()
        with CaptureQueriesContext(connection) as queries:
            response = client.get(path)
        if response.status_code != 200:
            sys.exit(f"GET {path}: {response.status_code} {response.content[:300]!r}")
        count = len(queries)  # now: the log is emptied again by the next request
        cpu = []
        for _ in range(repeats):
            start = time.process_time()
            client.get(path)
            cpu.append(time.process_time() - start)
        costs[path] = (count, 1000 * float(np.median(cpu)))
    return costs


def free_port():
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


def start_gunicorn(port, log, workers, threads):
    proc = subprocess.Popen(
        [str(Path(sys.executable).with_name("gunicorn")), "cutroom.wsgi:application",
         "--bind", f"127.0.0.1:{port}", "--workers", str(workers), "--threads", str(threads),
         "--access-logfile", "/dev/null", "--error-logfile", "-"],
        cwd=REPO, env=os.environ.copy(), stdout=log.open("w"), stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        try:
            urllib.request.urlopen(f"http://127.0.0.1:{port}/login/", timeout=2).close()
            return proc
        except OSError:
            if proc.poll() is not None:
                break
            time.sleep(0.2)
    sys.exit(f"gunicorn did not start:\n{log.read_text()}")


def run_wrk(url, token, seconds, connections, script):
    """(p50 ms, p95 ms, p99 ms, requests/s, errors) from wrk."""
    out = subprocess.run(
        ["wrk", "-t", str(min(2, connections)), "-c", str(connections), "-d", f"{seconds:g}s", "--timeout", "10s",
         "-s", str(script), "-H", f"Authorization: Token {token}", url],
        capture_output=True, text=True, check=True,
    ).stdout
    match = re.search(r"RESULT (\d+) (\d+) (\d+) (\d+) (\d+) (\d+)", out)
    if match is None:
        sys.exit(f"could not read wrk's output:\n{out}")
    p50, p95, p99, requests, duration_us, errors = map(int, match.groups())
    return p50 / 1000, p95 / 1000, p99 / 1000, requests / (duration_us / 1e6), errors


def run_python_client(url, token, seconds, connections):
    """The same figures from a bounded pool of Python threads (when wrk is missing)."""
    import http.client
    from urllib.parse import urlsplit

    parts, latencies, errors = urlsplit(url), [], [0]
    deadline = time.monotonic() + seconds
    path = parts.path + (f"?{parts.query}" if parts.query else "")

    def client():
        conn = http.client.HTTPConnection(parts.hostname, parts.port, timeout=10)
        while time.monotonic() < deadline:
            start = time.perf_counter()
            conn.request("GET", path, headers={"Authorization": f"Token {token}"})
            response = conn.getresponse()
            response.read()
            latencies.append(time.perf_counter() - start)
            errors[0] += response.status != 200

    threads = [threading.Thread(target=client) for _ in range(connections)]
    started = time.monotonic()
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    ms = np.array(latencies) * 1000
    p50, p95, p99 = np.percentile(ms, [50, 95, 99])
    return p50, p95, p99, len(ms) / (time.monotonic() - started), errors[0]


def load(tool, url, token, seconds, connections, script):
    if tool == "wrk":
        return run_wrk(url, token, seconds, connections, script)
    return run_python_client(url, token, seconds, connections)


def main():
    args = parse_args()
    name = f"cutroom_bench_captures_{os.getpid()}"
    var = Path(tempfile.mkdtemp(prefix="cutroom-bench-"))
    server = None
    try:
        url = scratch_database(args.postgres, name)
        start_django(unset=("CELERY_BROKER_URL",), DATABASE_URL=url, CUTROOM_VAR_DIR=str(var),
                     DB_CONN_MAX_AGE="60")
        started = time.perf_counter()
        token, project = seed(args.captures)
        seeded = time.perf_counter() - started
        middle = max(1, args.captures // 100)  # half way through pages of 50
        paths = [(label, path.format(project=project, middle=middle))
                 for label, path in SCENARIOS]
        costs = in_process_cost(token, [p for _, p in paths])
        from django.db import connections

        connections.close_all()
        port = free_port()
        server = start_gunicorn(port, var / "gunicorn.log", args.workers, args.threads)
        tool = "wrk" if shutil.which("wrk") else "python client"
        script = var / "report.lua"
        script.write_text(LUA)
        print(f"GET /api/captures/ on PostgreSQL, {args.captures} captures of the caller "
              f"(+1000 of another user; seeded in {seeded:.1f} s), gunicorn {args.workers} workers x "
              f"{args.threads} threads on loopback, {tool}, {args.connections} connections, "
              f"{args.seconds:g} s per scenario, page size 50; machine: {os.cpu_count()} "
              f"cores, load average {os.getloadavg()[0]:.1f} at start")
        print(f"{'scenario':<20} {'queries':>7} {'CPU ms':>7} {'p50 ms':>8} {'p95 ms':>8} "
              f"{'p99 ms':>8} {'req/s':>8} {'errors':>6}")
        worst = 0.0
        for label, path in paths:
            target = f"http://127.0.0.1:{port}{path}"
            load(tool, target, token, 2, args.connections, script)  # warm-up, not measured
            p50, p95, p99, rate, errors = load(
                tool, target, token, args.seconds, args.connections, script
            )
            worst = max(worst, p95)
            print(f"{label:<20} {costs[path][0]:>7} {costs[path][1]:>7.1f} {p50:>8.1f} {p95:>8.1f} {p99:>8.1f} "
                  f"{rate:>8.1f} {errors:>6}")
        verdict = "meets" if worst <= TARGET_MS else "MISSES"
        print(f"worst p95 {worst:.1f} ms ({verdict} the {TARGET_MS:g} ms target); CPU ms = "
              "median in-process CPU time of one request (view, serializers, JSON, driver)")
    finally:
        if server is not None:
            stop(server)
        try:
            from django.db import connections

            connections.close_all()
        except Exception:
            pass
        drop_database(args.postgres, name)
        shutil.rmtree(var, ignore_errors=True)

