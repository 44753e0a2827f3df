"""Review requests on a one-hour take: reads and edits stay fast, suggestions come from the worker.

Everything runs as `make up` runs it: a temporary SQLite database, the SQLite broker,
a Celery worker (2 processes) and gunicorn as subprocesses, started with the command lines
of ``scripts/up.py`` (its gunicorn sizing, its worker nice value). ``--old-serving``
starts them as they were before frames and signals answers were cached and bounded:
gunicorn 2 workers x 4 threads, the worker not niced, ``CUTROOM_HEAVY_REQUESTS=0`` and
``CUTROOM_ANSWER_CACHE_MB=0``, no bulk lane (``cutroom/lanes.py``; the new serving starts
its niced server as ``make up`` does). The data is seeded (``motionlib.synth``):

- a library of gold-labelled takes (``--library-minutes``, cut into 10-minute takes at
  their true boundaries, submitted by one annotator and adjudicated by a reviewer);
- the long take (``--minutes``, 432,000 frames for 60) with a finished run of the default
  detector, computed here on its frames; built from its frames, not a BVH upload (its
  text would be ~240 MB and ingest is not what this measures);
- a small 40-second take that another annotator keeps reviewing.

Measured, over HTTP with a token (wall-clock ms on the client):

1. The old path, where possible: the review response as it was before suggestions left
   it — the review plus a label suggestion for every unlabelled segment, computed by the
   previous ``segmentation.library.suggest_labels`` read from git history, with a cold
   cache (the per-process cache that never hit) — timed in this process.
2. The new path: review GET and edits (insert, label, move, delete a cut) p50/p95, and
   how long the worker takes until every suggestion of the review is stored.
3. Twenty annotators (threads of this process) opening the long take at the same
   moment, in ``--waves`` rounds
   (a page load: capture, me, projects, review, signal, suggestions and the first
   chunk of frames — the page streams the rest while the review is already usable;
   stored suggestions are deleted first, so the worker computes them during the first
   round), against the small capture's requests (review GET, label edit, capture GET)
   made one after another throughout by a process of its own, and alone before.

    .venv/bin/python -m benchmarks review-long-take -- [--minutes 60] [--library-minutes 60]
        [--repeats 40] [--pages 20] [--waves 3] [--old-serving]

``--browser`` measures instead what a person sees opening the long take in headless Chromium
(``/usr/bin/chromium``, the built ``frontend/dist``), served as ``make up`` serves it: the
first pose on screen and every lane drawn at full resolution (the page's
``data-first-pose-ms`` and ``data-lanes-ms``, milliseconds from navigation), and all poses
loaded, ``--browser-repeats`` page loads of each path alternating in the same run. The old
path is the previous pose loader (``?poses=json``: JSON chunks of at most 5,000 frames of
base64 float32, two requests in flight, ~90 requests for an hour); the new one asks for
600 poses at the playhead, then streams the rest of the take as raw float32 from
``/poses/``. No library is built for it.

    .venv/bin/python -m benchmarks review-long-take -- --browser [--minutes 60] [--browser-repeats 5]

Targets: review GET and edit p95 <= 100 ms; the small capture's p50 and p95 under the
load <= 2x alone; in Chromium, first pose <= 0.5 s, every lane drawn <= 2 s and every
pose of the hour <= 3 s.
"""

import argparse
import http.client
import json
import multiprocessing
import os
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time
import types
from pathlib import Path

import numpy as np

from benchmarks.harness import REPO
from benchmarks.harness.service import start_django, stop, up_script

TARGET_MS = 100.0
TARGET_FIRST_POSE_MS = 500.0
TARGET_ALL_POSES_MS = 3000.0
TARGET_LANES_MS = 2000.0
CHROMIUM = "/usr/bin/chromium"
TARGET_SLOWDOWN = 2.0
LIBRARY_TAKE_MINUTES = 10.0


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=60.0, help="length of the long take")
    parser.add_argument("--library-minutes", type=float, default=60.0)
    parser.add_argument("--repeats", type=int, default=40, help="requests of each kind")
    parser.add_argument("--pages", type=int, default=20, help="concurrent page loads")
    parser.add_argument("--waves", type=int, default=3, help="rounds of concurrent page loads")
    parser.add_argument("--old-repeats", type=int, default=3)
    parser.add_argument("--keep-suggestions", action="store_true",
                        help="leave stored suggestions in place: the worker stays idle during the loads")
    parser.add_argument("--old-serving", action="store_true",
                        help="gunicorn 2x4, worker not niced, no answer cache, no heavy-request bound")
    parser.add_argument("--browser", action="store_true",
                        help="only the page in Chromium: first pose and every lane drawn, old and new order")
    parser.add_argument("--browser-repeats", type=int, default=5, help="page loads of each order")
    return parser.parse_args()


def load():
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} on {os.cpu_count()} CPUs"


# ---- data ---------------------------------------------------------------------------------


def synth_capture(project, user, seed, minutes, detect=False):
    """A ready capture of a seeded synthetic take (positions stored), its true segments and,
    with ``detect``, a finished run of the default detector."""
    from django.core.files.base import ContentFile

    import motionlib
    from motionlib import synth
    from motionlib.segmenters import get_segmenter
    from segmentation.files import storage
    from segmentation.models import Capture, DetectionRun

    take, truth = synth.generate(seed=seed, fps=120.0, duration=minutes * 60)
    capture = Capture(
        project=project, uploaded_by=user, name=f"synth-{seed}.bvh", format="bvh",
        checksum=f"synth-{seed}-{minutes}", status="ready", fps=take.fps, n_frames=take.n_frames,
        n_joints=len(take.skeleton.names),
        skeleton={"joints": list(take.skeleton.names),
                  "parents": [int(p) for p in take.skeleton.parents], "height": 1.7, "up": "y"},
    )
    capture.original.save("take.bvh", ContentFile(b"built from frames, see the benchmark"), save=False)
    positions = np.asarray(motionlib.forward_kinematics(take), dtype="<f4")
    storage.save_npy(capture.positions, "positions.npy", positions)
    capture.save()
    if detect:
        segmenter = get_segmenter("default")
        result = segmenter(**segmenter.validate_params({})).fit_predict(take)
        run = DetectionRun(capture=capture, method="default", params={}, status="ready",
                           candidates=[{"frame": int(f), "confidence": round(float(c), 4)}
                                       for f, c in zip(result.cuts, result.confidence, strict=True)])
        storage.save_npz(run.signals, "signals.npz",
                         {k: np.asarray(v, dtype="<f4") for k, v in result.signals.items()})
        run.save()
    return capture, truth


def populate(args):
    from django.contrib.auth import get_user_model

    from accounts.models import ApiToken
    from motionlib import synth
    from segmentation import services
    from segmentation.models import LibrarySegment
    from segmentation.services import gold

    users = get_user_model().objects
    admin = users.create_user("admin")
    project = services.do_create_project(admin, "Benchmark studio")
    for name in synth.ACTIONS:
        services.do_add_label(project, name)
    names = ["librarian", "rachel", "ann", "small", *[f"viewer{i:02d}" for i in range(args.pages)]]
    people = {}
    for name in names:
        people[name] = users.create_user(name)
        services.do_set_member(project, name, "reviewer" if name == "rachel" else "annotator")
    started = time.perf_counter()
    n_takes = max(1, round(args.library_minutes / LIBRARY_TAKE_MINUTES))
    for i in range(n_takes):
        capture, truth = synth_capture(project, admin, 100 + i, args.library_minutes / n_takes)
        cuts, labels = [s for s, _, _ in truth[1:]], [label for _, _, label in truth]
        submit(capture, people["librarian"], cuts, labels)
        gold.do_save_gold(capture, people["rachel"], cuts, labels, version=0)
    print(f"library: {n_takes} takes, {LibrarySegment.objects.filter(is_gold=True).count()} gold "
          f"segments ({time.perf_counter() - started:.0f} s to build)")
    started = time.perf_counter()
    long_take, _ = synth_capture(project, admin, 11, args.minutes, detect=True)
    run = long_take.latest_finished_run()
    print(f"long take: {long_take.n_frames} frames at 120 fps, {len(run.candidates)} candidate "
          f"cuts from the default detector ({time.perf_counter() - started:.0f} s to build)")
    small, _ = synth_capture(project, admin, 12, 40 / 60, detect=True)
    services.get_or_create_review(long_take, people["ann"])
    services.get_or_create_review(small, people["small"])
    tokens = {name: ApiToken.objects.issue(user)[1] for name, user in people.items()}
    return types.SimpleNamespace(long=long_take, small=small, tokens=tokens, people=people)


def submit(capture, user, cuts, labels):
    from segmentation import services
    from segmentation.models import Cut, SegmentLabel

    review = services.get_or_create_review(capture, user)
    Cut.objects.bulk_create(Cut(review=review, origin="inserted", fate="accepted", frame=f) for f in cuts)
    kept = [None, *review.cuts.order_by("frame").values_list("id", flat=True)]
    named = {label.name: label for label in capture.project.labels.all()}
    SegmentLabel.objects.bulk_create(SegmentLabel(review=review, cut_id=c, label=named[n])
                                     for c, n in zip(kept, labels, strict=True))
    services.do_submit_review(review, user, review.version)


# ---- the old path -------------------------------------------------------------------------


def old_library():
    """The module ``segmentation.library`` as it was when it still suggested labels on the
    review request, or None if git history does not have it."""
    try:
        revs = subprocess.run(["git", "log", "--format=%H", "-S", "def suggest_labels", "--",
                               "segmentation/library.py"], cwd=REPO, capture_output=True,
                              text=True, check=True).stdout.split()
        # The newest commit that touched it removed it; its parent still has it.
        source = subprocess.run(["git", "show", f"{revs[0]}^:segmentation/library.py"], cwd=REPO,
                                capture_output=True, text=True, check=True).stdout
    except (subprocess.CalledProcessError, IndexError, OSError):
        return None
    # Modules it imports that have since moved: the models now live in one package.
    import segmentation.models

    for moved in ("models_library", "models_reviews", "models_captures", "models_jobs"):
        sys.modules.setdefault(f"segmentation.{moved}", segmentation.models)
    module = types.ModuleType("old_library")
    exec(compile(source, "old segmentation/library.py", "exec"), module.__dict__)
    return module


def time_old_path(data, repeats):
    from django.core.cache import cache

    from segmentation.api.common.serializers.reviews import ReviewSerializer
    from segmentation.models import Review

    old = old_library()
    if old is None:
        return None
    review = Review.objects.get(capture=data.long, annotator=data.people["ann"])
    times = []
    for _ in range(repeats):
        cache.clear()
        started = time.perf_counter()
        body = ReviewSerializer(review).data
        old.suggest_labels(review, review.segments())
        times.append((time.perf_counter() - started) * 1000)
        assert body["segments"]
    return times


# ---- HTTP ---------------------------------------------------------------------------------


class Client:
    """One keep-alive connection with a user's token."""

    def __init__(self, port, token):
        self.port, self.token = port, token
        self.conn = http.client.HTTPConnection("127.0.0.1", port, timeout=300)

    def call(self, method, path, body=None, parse=True):
        headers = {"Authorization": f"Token {self.token}"}
        data = None
        if body is not None:
            data, headers["Content-Type"] = json.dumps(body).encode(), "application/json"
        started = time.perf_counter()
        for attempt in range(2):
            try:
                self.conn.request(method, path, body=data, headers=headers)
                response = self.conn.getresponse()
                content = response.read()
                break
            except (http.client.HTTPException, ConnectionError):
                # The server closed the idle keep-alive connection: open another one.
                self.conn.close()
                self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=300)
                if attempt:
                    raise
        elapsed = (time.perf_counter() - started) * 1000
        if response.status >= 400:
            raise RuntimeError(f"{method} {path} -> {response.status}: {content[:300]!r}")
        return elapsed, json.loads(content) if content and parse else None


def time_new_path(client, capture, repeats):
    """{kind: [ms]} of review GET and edits on the annotator's review of ``capture``."""
    url = f"/api/captures/{capture.pk}/review/"
    times = {"GET review": [], "insert cut": [], "label segment": [], "move cut": [], "delete cut": []}
    _, review = client.call("GET", url)
    kept = sorted(c["frame"] for c in review["cuts"] if c["fate"] != "deleted")
    gaps = [(a, b) for a, b in zip(kept[:-1], kept[1:], strict=True) if b - a > 20]
    for i in range(repeats):
        ms, review = client.call("GET", url)
        times["GET review"].append(ms)
        a, b = gaps[(i * 7919) % len(gaps)]
        frame = (a + b) // 2
        ms, review = client.call("POST", url + "cuts/", {"frame": frame, "version": review["version"]})
        times["insert cut"].append(ms)
        index = next(s["index"] for s in review["segments"] if s["start"] == frame)
        ms, review = client.call("PATCH", url + f"segments/{index}/", {"label": "walk", "version": review["version"]})
        times["label segment"].append(ms)
        cut = next(c for c in review["cuts"] if c["frame"] == frame and c["fate"] != "deleted")
        ms, review = client.call("PATCH", url + f"cuts/{cut['id']}/", {"frame": frame + 3, "version": review["version"]})
        times["move cut"].append(ms)
        ms, review = client.call("PATCH", url + f"cuts/{cut['id']}/", {"fate": "deleted", "version": review["version"]})
        times["delete cut"].append(ms)
    return times


def wait_for_suggestions(client, capture, timeout=1800):
    """Seconds from the first ask until no suggestion of the review is pending."""
    url = f"/api/captures/{capture.pk}/review/suggestions/"
    started = time.perf_counter()
    asks = []
    while time.perf_counter() - started < timeout:
        ms, body = client.call("GET", url)
        asks.append(ms)
        if not body["pending"]:
            return time.perf_counter() - started, len(body["suggestions"]), asks
        time.sleep(0.5)
    raise SystemExit(f"suggestions still pending after {timeout} s")


PAGE_REQUESTS = ("capture", "me", "projects", "review", "signal", "suggestions", "frames")


def page_load(client, capture):
    """The requests the review page makes before it shows the review: {name: ms}."""
    base = f"/api/captures/{capture.pk}/"
    paths = (base, "/api/me/", "/api/projects/", base + "review/", base + "signal/?max_points=4000",
             base + "review/suggestions/", base + "frames/?start=0&stop=5000&step=1")
    started = time.perf_counter()
    times = {name: client.call("GET", path, parse=False)[0]
             for name, path in zip(PAGE_REQUESTS, paths, strict=True)}
    times["page"] = (time.perf_counter() - started) * 1000
    return times


SMALL_REQUESTS = ("GET review", "PATCH label", "GET capture")


def small_round(client, capture, state):
    """One round of the small capture's requests: review GET, a label edit, capture GET."""
    url = f"/api/captures/{capture.pk}/review/"
    out = []
    ms, review = client.call("GET", url)
    out.append(ms)
    state["label"] = None if state.get("label") else "walk"
    ms, _ = client.call("PATCH", url + "segments/0/", {"label": state["label"], "version": review["version"]})
    out.append(ms)
    ms, _ = client.call("GET", f"/api/captures/{capture.pk}/")
    out.append(ms)
    return out


def small_client(port, token, capture_id, rounds, begin, stop_at, out):
    """The small capture's requests, one after another, in a process of its own (so the
    viewers' threads in this process never hold its clock): ``rounds`` rounds, or until
    ``stop_at`` is set. Sends its list of ms to ``out``."""
    client, state, times = Client(port, token), {}, []
    capture = types.SimpleNamespace(pk=capture_id)
    begin.wait()
    while (len(times) < 3 * rounds) if rounds else not stop_at.is_set():
        times.extend(small_round(client, capture, state))
    out.send(times)


def run_small(port, data, begin, rounds=0, stop_at=None):
    reader, writer = multiprocessing.Pipe(duplex=False)
    proc = multiprocessing.get_context("fork").Process(
        target=small_client,
        args=(port, data.tokens["small"], data.small.pk, rounds, begin, stop_at, writer))
    proc.start()
    return proc, reader


def time_under_load(port, data, repeats, waves, keep_suggestions=False):
    """The small capture's request times alone, then during ``waves`` rounds of every viewer
    opening the long take at the same moment; and the page load times."""
    from segmentation.models import LabelSuggestion, SuggestionRequest

    fork = multiprocessing.get_context("fork")
    begin = fork.Event()
    proc, reader = run_small(port, data, begin, rounds=repeats)
    begin.set()
    alone = reader.recv()
    proc.join()
    if not keep_suggestions:
        LabelSuggestion.objects.filter(capture=data.long).delete()
        SuggestionRequest.objects.filter(capture=data.long).delete()
    viewers = {name: Client(port, token) for name, token in data.tokens.items() if name.startswith("viewer")}
    loaded, pages, errors = [], [], []  # loaded: one list per wave

    def viewer(client, go):
        go.wait()
        try:
            pages.append(page_load(client, data.long))
        except Exception as exc:  # reported below, never hidden
            errors.append(str(exc))

    for _ in range(waves):
        go = threading.Barrier(len(viewers) + 1)
        threads = [threading.Thread(target=viewer, args=(client, go)) for client in viewers.values()]
        for thread in threads:
            thread.start()
        begin, stop_at = fork.Event(), fork.Event()
        proc, reader = run_small(port, data, begin, stop_at=stop_at)
        go.wait()
        begin.set()
        for thread in threads:
            thread.join()
        stop_at.set()
        loaded.append(reader.recv())
        proc.join()
    return alone, loaded, pages, errors


# ---- processes ----------------------------------------------------------------------------


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def start(argv, log, ready, env=None):
    handle = log.open("w")
    proc = subprocess.Popen(argv, cwd=REPO, env=env or os.environ.copy(), stdout=handle,
                            stderr=subprocess.STDOUT, process_group=0)  # as make up: one session
    deadline = time.monotonic() + 90
    while not ready():
        if proc.poll() is not None or time.monotonic() > deadline:
            sys.exit(f"{argv[0]} did not start:\n{log.read_text()[-3000:]}")
        time.sleep(0.2)
    return proc


def answers(port):
    try:
        socket.create_connection(("127.0.0.1", port), timeout=1).close()
        return True
    except OSError:
        return False


def serving(old, var, port):
    """(worker argv, gunicorn argv, bulk lane server (up.py's Child) or None, description)
    as `make up` starts them, or as before. Sets the environment the processes get."""
    up, env = up_script(), os.environ.copy()
    env["CUTROOM_VAR_DIR"] = str(var)
    worker_argv = up.worker(env, var, 2).argv
    bulk = None if old else up.bulk_web(env, var)
    web_argv = up.web(env, var, "127.0.0.1", port).argv
    if old:
        os.environ.update(CUTROOM_HEAVY_REQUESTS="0", CUTROOM_ANSWER_CACHE_MB="0",
                          CUTROOM_BULK_REQUESTS="0", CUTROOM_BULK_SOCKET="")
        worker_argv = worker_argv[worker_argv.index(str(Path(sys.executable).parent / "celery")):]
        web_argv[web_argv.index("--workers") + 1], web_argv[web_argv.index("--threads") + 1] = "2", "4"
    else:
        os.environ["CUTROOM_BULK_SOCKET"] = env["CUTROOM_BULK_SOCKET"]
    from django.conf import settings

    heavy = os.environ.get("CUTROOM_HEAVY_REQUESTS", settings.CUTROOM_HEAVY_REQUESTS)
    cache_mb = os.environ.get("CUTROOM_ANSWER_CACHE_MB", settings.CUTROOM_ANSWER_CACHE_MB)
    workers, threads = (web_argv[web_argv.index(f"--{k}") + 1] for k in ("workers", "threads"))
    niced = f"nice {worker_argv[2]}" if worker_argv[0] == "nice" else "not niced"
    lane = ("no bulk lane" if old else
            f"bulk lane (CUTROOM_BULK_REQUESTS={settings.CUTROOM_BULK_REQUESTS}) on its own server, "
            f"nice {bulk.argv[2]}" if bulk else "bulk lane in the web server's processes")
    return worker_argv, web_argv, bulk, (
        f"{'OLD' if old else 'NEW'} serving: gunicorn {workers} workers x {threads} threads, "
        f"worker {niced}, CUTROOM_HEAVY_REQUESTS={heavy}, CUTROOM_ANSWER_CACHE_MB={cache_mb}, {lane}")


# ---- the page in Chromium -------------------------------------------------------------------

BROWSER_PATHS = {"OLD (JSON chunks, ?poses=json)": "?poses=json",
                 "NEW (first pose, then one float32 stream)": ""}


def open_in_chromium(browser, port, capture, query, password):
    """(first pose, every lane drawn, all poses loaded) in ms from navigation, one page load
    by a fresh context (no cached answers of the last load)."""
    from playwright.sync_api import expect

    context = browser.new_context(viewport={"width": 1440, "height": 900})
    try:
        page = context.new_page()
        base = f"http://127.0.0.1:{port}"
        page.goto(f"{base}/login/?next=/")
        page.fill("#id_username", "ann")
        page.fill("#id_password", password)
        page.click("button[type=submit]")
        page.wait_for_url(f"{base}/")
        page.goto(f"{base}/captures/{capture.pk}/{query}")
        timeline, loading = page.get_by_test_id("timeline"), page.get_by_test_id("frames-loading")
        expect(page.get_by_test_id("viewport")).to_have_attribute("data-first-pose-ms", re.compile(r"^\d+$"), timeout=120_000)
        expect(timeline).to_have_attribute("data-lanes-ms", re.compile(r"^\d+$"), timeout=120_000)
        expect(loading).to_have_attribute("data-done", re.compile(r"^\d+$"), timeout=120_000)
        # data-done counts from when the poses were first asked for; as the others, from navigation.
        done = page.evaluate("""() => Number(document.querySelector('[data-testid=frames-loading]').dataset.done)
            + performance.getEntriesByType('resource').find((e) => /[/](frames|poses)[/]/.test(e.name)).startTime""")
        return (int(page.get_by_test_id("viewport").get_attribute("data-first-pose-ms")),
                int(timeline.get_attribute("data-lanes-ms")), done)
    finally:
        context.close()


def time_in_chromium(port, capture, repeats, password):
    """{path: {"first pose": [ms], "every lane drawn": [ms], "all poses loaded": [ms]}}."""
    from playwright.sync_api import sync_playwright

    from tests.e2e.conftest import CHROMIUM_ARGS

    times = {name: {"first pose": [], "every lane drawn": [], "all poses loaded": []} for name in BROWSER_PATHS}
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            open_in_chromium(browser, port, capture, "", password)  # warm the answer caches
            for _ in range(repeats):
                for name, query in BROWSER_PATHS.items():
                    for kind, ms in zip(times[name], open_in_chromium(browser, port, capture, query, password),
                                        strict=True):
                        times[name][kind].append(ms)
        finally:
            browser.close()
    return times


def browser_main(args, var):
    """The long take opened in Chromium, old and new request order in the same run."""
    from django.contrib.auth import get_user_model

    from segmentation import services

    password = "benchmark-password"
    admin = get_user_model().objects.create_user("admin")
    project = services.do_create_project(admin, "Benchmark studio")
    get_user_model().objects.create_user("ann", password=password)
    services.do_set_member(project, "ann", "annotator")
    started = time.perf_counter()
    long_take, _ = synth_capture(project, admin, 11, args.minutes, detect=True)
    services.get_or_create_review(long_take, get_user_model().objects.get(username="ann"))
    lanes = len(storage_signals(long_take))
    print(f"long take: {long_take.n_frames:,} frames at 120 fps, {long_take.n_joints} joints, {lanes} "
          f"signal lanes ({time.perf_counter() - started:.0f} s to build)")
    port = free_port()
    worker_argv, web_argv, bulk, described = serving(False, var, port)
    print(described)
    procs = []
    try:
        if bulk:
            sock = Path(os.environ["CUTROOM_BULK_SOCKET"])
            procs.append(start(bulk.argv, var / "web-bulk.log", sock.exists, env=bulk.env))
        procs.append(start(web_argv, var / "web.log", lambda: answers(port)))
        print(f"before: {load()}")
        times = time_in_chromium(port, long_take, args.browser_repeats, password)
        print(f"\nheadless Chromium, {args.browser_repeats} page loads of each order, alternating "
              f"(ms from navigation; a fresh browser context each):")
        print(f"{'page load':<52} {'n':>5} {'p50':>9} {'p95':>9} {'max':>9}")
        for name, kinds in times.items():
            for kind, values in kinds.items():
                target = {"first pose": TARGET_FIRST_POSE_MS, "every lane drawn": TARGET_LANES_MS,
                          "all poses loaded": TARGET_ALL_POSES_MS}.get(kind)
                row(f"{name}: {kind}", values, target, width=52)
        print(f"\nafter: {load()}")
    finally:
        for proc in reversed(procs):
            stop(proc)


def storage_signals(capture):
    from segmentation.files import storage

    run = capture.latest_finished_run()
    return storage.load_npz(run.signals) if run and run.signals else {}


# ---- report -------------------------------------------------------------------------------


def pct(values, q):
    return float(np.percentile(values, q)) if values else float("nan")


def row(name, values, target=None, width=34):
    p95 = pct(values, 95)
    verdict = "" if target is None else ("ok" if p95 <= target else "MISSED")
    print(f"{name:<{width}} {len(values):>5} {statistics.median(values):>9.1f} {p95:>9.1f} {max(values):>9.1f}  {verdict}")


def main():
    args = parse_args()
    var = Path(tempfile.mkdtemp(prefix="cutroom-review-bench-"))
    procs = []
    try:
        start_django(unset=("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT", "CELERY_BROKER_DIR"),
                     CUTROOM_VAR_DIR=str(var))
        print(f"embedded default (SQLite, SQLite broker) in {var}; {load()}")
        if args.browser:
            return browser_main(args, var)
        data = populate(args)
        old = time_old_path(data, args.old_repeats)

        port = free_port()
        worker_argv, web_argv, bulk, described = serving(args.old_serving, var, port)
        print(described)
        worker_log = var / "worker.log"
        procs.append(start(worker_argv, worker_log, lambda: " ready." in worker_log.read_text()))
        if bulk:
            sock = Path(os.environ["CUTROOM_BULK_SOCKET"])
            procs.append(start(bulk.argv, var / "web-bulk.log", sock.exists, env=bulk.env))
        procs.append(start(web_argv, var / "web.log", lambda: answers(port)))
        ann = Client(port, data.tokens["ann"])
        ann.call("GET", "/api/me/")  # warm both connections' first request
        ready_s, n_suggested, asks = wait_for_suggestions(ann, data.long)
        new = time_new_path(ann, data.long, args.repeats)
        alone, loaded, pages, errors = time_under_load(port, data, args.repeats, args.waves,
                                                       args.keep_suggestions)

        print(f"\n{'request (ms, client wall clock)':<34} {'n':>5} {'p50':>9} {'p95':>9} {'max':>9}")
        if old is None:
            print(f"{'OLD review GET (with suggestions)':<34} not available (no git history)")
        else:
            row("OLD review GET (with suggestions)", old, TARGET_MS)
        for kind, values in new.items():
            row(f"NEW {kind}", values, TARGET_MS)
        row("NEW GET suggestions (polling)", asks)
        print(f"worker stored all {n_suggested} suggestions {ready_s:.1f} s after the page first asked")
        print(f"\n{args.waves} x {args.pages} page loads of the long take started at once "
              f"({len(pages)} done, {len(errors)} errors; stored suggestions "
              f"{'kept' if args.keep_suggestions else 'deleted first'}) vs the small capture's requests:")
        row("long take page load (7 requests)", [p["page"] for p in pages])
        for name in PAGE_REQUESTS:
            row(f"  of which GET {name}", [p[name] for p in pages])
        row("small capture, alone", alone)
        for wave, values in enumerate(loaded, 1):
            row(f"small capture, during wave {wave}", values)
        loaded = [ms for values in loaded for ms in values]
        row("small capture, during all waves", loaded)
        for i, kind in enumerate(SMALL_REQUESTS):  # each round makes these, in this order
            row(f"  {kind}, alone", alone[i::3])
            row(f"  {kind}, during the waves", loaded[i::3])
        for q in (50, 95):
            ratio = pct(loaded, q) / pct(alone, q)
            print(f"small capture p{q} slowdown: {ratio:.2f}x  "
                  f"{'ok' if ratio <= TARGET_SLOWDOWN else 'MISSED'} (target <= {TARGET_SLOWDOWN:g}x)")
        for error in errors[:5]:
            print("error:", error)
        print(f"\n{load()}")
    finally:
        for proc in reversed(procs):
            stop(proc)
        shutil.rmtree(var, ignore_errors=True)

