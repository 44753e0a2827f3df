"""The review page's playback and scrubbing at 38 s, 10 minutes and 60 minutes: old and new
front end in the same run, in headless Chromium (software WebGL, as the browser tests).

The takes are CMU 13_29 (38 s at 120 fps, 31 joints) and its motion repeated to 10 and 60
minutes, with the default detector's candidates and signals repeated with it
(``tests/e2e/long_takes.py``; ~80 and ~470 candidates). One SQLite installation serves both
front ends in turn: the web server as ``make up`` starts it (``scripts/up.py``, no bulk
lane), pointed by ``CUTROOM_FRONTEND_DIST`` at

- OLD: the front end at ``--old-commit`` (default baf26d2, before the timeline drew its still
  parts once per view), built with ``npm run build`` in a git worktree under /tmp whose
  ``node_modules`` is this checkout's;
- NEW: this checkout's ``frontend/dist`` (build it first).

Each take is opened once per build, in alternating order, and measured once every pose and
every lane at full resolution has loaded, the page has been left 5 s and played 30 frames
untimed:

- playback: the interval between animation frames while playing from frame 0, with about
  a minute in view (Home, "Fit", then "+" until about a minute is in view: the new page
  opens a take over 5 minutes on such a working window) and at "Fit" (the whole take in
  view; the old page opens every take so), alternated twice, ``--frames`` in all per view;
- scrub latency: a pointer dragged along the ruler with the real mouse (CDP), ms from each
  pointermove event's timestamp to the end of the animation frame that drew it. Done in the
  same views in both builds: Home, "Fit", then "+" until about a minute is in view; and at
  "Fit". The press is at least 8 px from any cut, since the old page grabs a cut within
  6 px even on the ruler (at "Fit" on the hour no such point exists: n/a for the old page).

    .venv/bin/python -m benchmarks review-playback -- [--frames 120] [--moves 40]

Target: a 60-minute take plays within 1.5x the redraw interval of the 38-s take (median),
in each view.
"""

import argparse
import math
import os
import re
import shutil
import socket
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.harness import REPO
from benchmarks.harness.service import start_django, stop, up_script

CHROMIUM = "/usr/bin/chromium"
PASSWORD = "benchmark-password"
TAKES = {"38 s": None, "10 min": 600, "60 min": 3600}
TARGET_RATIO = 1.5
ZOOM_STEP = 1.5  # the "+" button's factor, the same in both builds


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--old-commit", default="baf26d2")
    parser.add_argument("--frames", type=int, default=120, help="animation frames timed while playing")
    parser.add_argument("--moves", type=int, default=40, help="pointer moves of the scrub")
    return parser.parse_args()


def load():
    one, five, fifteen = os.getloadavg()
    return f"load average {one:.2f} {five:.2f} {fifteen:.2f} on {os.cpu_count()} CPUs"


# ---- builds and server ----------------------------------------------------------------------


def old_build(commit):
    """frontend/dist of ``commit``, built in a worktree (/tmp/old-front when it is at that
commit, else one made under /tmp) whose node_modules links to this checkout's."""
    tree = Path("/tmp/old-front")
    head = subprocess.run(["git", "-C", str(tree), "rev-parse", "HEAD"], capture_output=True, text=True).stdout
    if not head.startswith(commit):
        tree = Path(tempfile.gettempdir()) / f"cutroom-front-{commit}"
    if not (tree / "frontend" / "dist" / "index.html").is_file():
        if not tree.exists():
            subprocess.run(["git", "worktree", "add", "--detach", str(tree), commit], cwd=REPO, check=True,
                           capture_output=True)
        modules = tree / "frontend" / "node_modules"
        if not modules.exists():
            modules.symlink_to((REPO / "frontend" / "node_modules").resolve())
        subprocess.run(["npm", "run", "build"], cwd=tree / "frontend", check=True, capture_output=True)
    return tree / "frontend" / "dist"


def free_port():
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return sock.getsockname()[1]


def serve(dist, var):
    """The web server as `make up` starts it, serving the front end in ``dist``; (process, port)."""
    port = free_port()
    env = {**os.environ, "CUTROOM_VAR_DIR": str(var), "CUTROOM_FRONTEND_DIST": str(dist), "CUTROOM_BULK_SOCKET": ""}
    child = up_script().web(env, var, "127.0.0.1", port)
    log = (var / f"web-{port}.log").open("w")
    proc = subprocess.Popen(child.argv, cwd=REPO, env=env, stdout=log, stderr=subprocess.STDOUT, process_group=0)
    deadline = time.monotonic() + 90
    while True:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            return proc, port
        except OSError:
            if proc.poll() is not None or time.monotonic() > deadline:
                sys.exit(f"the web server did not start: {(var / f'web-{port}.log').read_text()[-2000:]}")
            time.sleep(0.2)


def populate():
    """The three takes, owned by a project where "ann" annotates; {name: capture}."""
    from django.contrib.auth import get_user_model

    from segmentation import services
    from tests.e2e.long_takes import repeated_capture, take_13_29

    users = get_user_model().objects
    admin = users.create_user("admin")
    project = services.do_create_project(admin, "Benchmark studio")
    users.create_user("ann", password=PASSWORD)
    services.do_set_member(project, "ann", "annotator")
    take = take_13_29()[0]
    captures = {}
    for name, seconds in TAKES.items():
        seconds = seconds or take.n_frames / take.fps
        captures[name] = repeated_capture(project, admin, seconds, name=f"13_29 {name}.bvh")
        run = captures[name].latest_finished_run()
        print(f"{name}: {captures[name].n_frames:,} frames, {len(run.candidates)} candidates")
    return captures


# ---- in the browser -------------------------------------------------------------------------

PLAY = """async (frames) => {
    const times = [];
    await new Promise((done) => {
        const tick = (t) => { times.push(t); times.length <= frames ? requestAnimationFrame(tick) : done(); };
        document.querySelector("[data-testid=play]").click();
        requestAnimationFrame(tick);
    });
    document.querySelector("[data-testid=play]").click();
    return times.slice(1).map((t, i) => t - times[i]);
}"""

# Registered after the timeline's own listener, so its animation frame callback runs after the draw.
WATCH_SCRUB = """() => {
    window.scrubLatencies = [];
    if (window.scrubWatched) return;
    window.scrubWatched = true;
    document.querySelector("[data-testid=timeline] canvas").addEventListener("pointermove", (e) => {
        if (!e.buttons) return;
        const t0 = e.timeStamp;
        requestAnimationFrame(() => window.scrubLatencies.push(performance.now() - t0));
    });
}"""


def open_take(context, port, capture):
    from playwright.sync_api import expect

    page = context.new_page()
    page.goto(f"http://127.0.0.1:{port}/captures/{capture.pk}/")
    expect(page.get_by_test_id("timeline")).to_have_attribute("data-lanes-ms", re.compile(r"^\d+$"), timeout=300_000)
    expect(page.get_by_test_id("frames-loading")).to_have_attribute("data-done", re.compile(r"^\d+$"), timeout=300_000)
    # Let the page settle after loading an hour of poses (garbage collection, late requests),
    # then play a little untimed, so no build's first measure pays for its warm-up.
    page.wait_for_timeout(5000)
    play(page, 30)
    return page


def play(page, frames):
    page.keyboard.press("Home")
    return page.evaluate(PLAY, frames)


def zoom_to(page, capture, zoomed):
    """Home, "Fit", then with ``zoomed`` "+" until about a minute is in view; the span in frames."""
    page.keyboard.press("Home")
    page.get_by_test_id("zoom-fit").click()
    zooms = max(0, round(math.log(capture.n_frames / (60 * capture.fps)) / math.log(ZOOM_STEP))) if zoomed else 0
    for _ in range(zooms):
        page.get_by_test_id("zoom-in").click()
    return capture.n_frames / ZOOM_STEP**zooms


def scrub(page, capture, moves, zoomed, old):
    """Scrub latencies (ms) along the ruler, over about a minute of the take (``zoomed``) or
    the whole take, the same view in both builds; None when the old page offers no press
    point at least 8 px from every cut (it would grab one instead of seeking)."""
    span = zoom_to(page, capture, zoomed)
    box = page.locator("[data-testid=timeline] canvas").bounding_box()
    xs = [c["frame"] / span * box["width"] for c in capture.latest_finished_run().candidates if c["frame"] < span]
    start = next((x for x in np.arange(20.0, box["width"] / 3) if all(abs(x - c) > 8 for c in xs)), None)
    if start is None:
        if old:
            return None
        start = 20.0  # the new page never grabs a cut from the ruler
    page.evaluate(WATCH_SCRUB)
    y = box["y"] + 12
    page.mouse.move(box["x"] + start, y)
    page.mouse.down()
    for i in range(1, moves + 1):
        page.mouse.move(box["x"] + start + (box["width"] * 0.6) * i / moves, y)
    page.mouse.up()
    page.wait_for_timeout(300)
    return page.evaluate("window.scrubLatencies")


def measure(browser, port, capture, args, old):
    context = browser.new_context(viewport={"width": 1440, "height": 900})
    try:
        page = context.new_page()
        page.goto(f"http://127.0.0.1:{port}/login/?next=/")
        page.fill("#id_username", "ann")
        page.fill("#id_password", PASSWORD)
        page.click("button[type=submit]")
        page.wait_for_url(f"http://127.0.0.1:{port}/")
        page = open_take(context, port, capture)
        times = {"play, 1-min view": [], "play, Fit": []}
        # Alternated, so neither view gets the page's quieter moments.
        for _ in range(2):
            for name, zoomed in (("play, 1-min view", True), ("play, Fit", False)):
                zoom_to(page, capture, zoomed)
                times[name] += play(page, args.frames // 2)
        return {**times,
                "scrub, 1-min view": scrub(page, capture, args.moves, True, old),
                "scrub, Fit": scrub(page, capture, args.moves, False, old)}
    finally:
        context.close()


# ---- report ---------------------------------------------------------------------------------


def pct(values, q):
    return float(np.percentile(values, q)) if values else float("nan")


def report(results):
    print(f"\n{'build':<5} {'take':<7} {'measure':<17} {'n':>4} {'median ms':>10} {'p95 ms':>8} {'max ms':>8}")
    for (build, take), kinds in results.items():
        for kind, values in kinds.items():
            if values is None:
                print(f"{build:<5} {take:<7} {kind:<17}  n/a: every press on its ruler is within 8 px of a cut, "
                      "which the old page grabs")
                continue
            print(f"{build:<5} {take:<7} {kind:<17} {len(values):>4} {statistics.median(values):>10.1f} "
                  f"{pct(values, 95):>8.1f} {max(values):>8.1f}")
    print()
    for build in ("OLD", "NEW"):
        for kind in ("play, 1-min view", "play, Fit"):
            short = statistics.median(results[(build, "38 s")][kind])
            hour = statistics.median(results[(build, "60 min")][kind])
            ratio = hour / short
            verdict = "ok" if ratio <= TARGET_RATIO else "MISSED"
            print(f"{build} {kind}: 60 min / 38 s median redraw interval = {hour:.1f} / {short:.1f} ms "
                  f"= {ratio:.2f}x  {verdict} (target <= {TARGET_RATIO}x)")


def run(args, var):
    from playwright.sync_api import sync_playwright

    from tests.e2e.conftest import CHROMIUM_ARGS

    builds = {"OLD": old_build(args.old_commit), "NEW": REPO / "frontend" / "dist"}
    if not (builds["NEW"] / "index.html").is_file():
        sys.exit("frontend/dist is missing: cd frontend && npm run build")
    print(f"OLD front end: {args.old_commit} ({builds['OLD']}); NEW: this checkout's frontend/dist")
    captures = populate()
    results = {}
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            for i, take in enumerate(TAKES):
                order = ["OLD", "NEW"] if i % 2 == 0 else ["NEW", "OLD"]
                for build in order:
                    proc, port = serve(builds[build], var)
                    try:
                        print(f"{build} {take}: {load()}", flush=True)
                        results[(build, take)] = measure(browser, port, captures[take], args, build == "OLD")
                    finally:
                        stop(proc)
        finally:
            browser.close()
    results = {key: results[key] for key in sorted(results, key=lambda k: (k[0] != "OLD", list(TAKES).index(k[1])))}
    report(results)
    print(f"\nafter: {load()}")


def main():
    args = parse_args()
    var = Path(tempfile.mkdtemp(prefix="cutroom-playback-bench-"))
    try:
        start_django(unset=("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT", "CELERY_BROKER_DIR"),
                     CUTROOM_VAR_DIR=str(var))
        print(f"embedded default (SQLite) in {var}; headless Chromium {CHROMIUM}, software WebGL; {load()}")
        run(args, var)
    finally:
        shutil.rmtree(var, ignore_errors=True)


if __name__ == "__main__":
    main()
