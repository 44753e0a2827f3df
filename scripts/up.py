"""Run Cutroom on the embedded default: migrate, demo data, a Celery worker and the web server.

``make up`` calls this after installing the Python packages and building the front end::

    python scripts/up.py [--host 127.0.0.1] [--port 8000] [--concurrency 2] [--no-demo]
                         [--no-shared-data]

With no environment set, everything lives under ``var/`` (SQLite, the SQLite broker
file, uploaded originals, logs). The worker and gunicorn run as child processes with
their logs in ``var/log/``; a worker or web server that dies is reported (with the end of
its log) and restarted (a dead worker's jobs are requeued; a worker that looks stuck is
first sent its waiting jobs again, in case their message was lost); Ctrl-C (or SIGTERM) stops both and waits for
them. Running it again is safe: migrations are applied when missing and demo data is added
once (``manage.py demo`` leaves an existing demo project as its admins keep it).
"""

import argparse
import os
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
# Worker restarts beyond this many in the window wait, longer each time (up to the
# longest pause), instead of looping fast on a worker that cannot start.
RESTARTS_IN_WINDOW = 5
RESTART_WINDOW = 600.0
LONGEST_PAUSE = 300.0
# The workers run at this nice value, so on a small machine the web server's requests
# win the CPU over detection and suggestion jobs.
WORKER_NICE = 10
# gunicorn: 2 processes of 32 threads. A thread waiting in its process's bulk lane
# (cutroom/lanes.py; at most CUTROOM_BULK_QUEUE = 24 of them) or for a CUTROOM_HEAVY_REQUESTS
# slot sleeps (no CPU, no GIL); with this many threads a light request still finds a free
# one while 20 page loads of a long take are in progress.
WEB_WORKERS, WEB_THREADS = 2, 32
# The bulk lane's web server (cutroom/lanes.py): requests about long takes, handed to it
# by the web server over a Unix socket under var/run/, at the workers' lower CPU priority
# (benchmarks/service/review_long_take.py, twenty page loads of a one-hour take: nice 10 kept a
# small capture's requests within 1.4-1.5x of alone at p95, nice 5 within 1.9-2.1x).
BULK_NICE = 10
# FBX files Blender converts at once, each in a pool process of the convert worker with a
# Blender of its own: a file that hangs Blender holds one slot until MOTIONLIB_BLENDER_TIMEOUT
# while the other slots keep serving the queue (CUTROOM_CONVERT_SLOTS).
CONVERT_SLOTS = 2
# What stops everything; SIGHUP too: the children are in the terminal's session, and
# closing it must stop them.
STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def parse_args(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1")
    parser.add_argument("--port", type=int, default=8000)
    parser.add_argument("--concurrency", type=int, default=2, help="worker processes")
    parser.add_argument("--no-demo", action="store_true", help="skip `manage.py demo`")
    parser.add_argument(
        "--no-shared-data", action="store_true", help="demo without the CMU takes"
    )
    return parser.parse_args(argv)


def say(message):
    print(f"[up] {message}", flush=True)


def var_dir():
    return Path(os.environ.get("CUTROOM_VAR_DIR") or REPO / "var")


def environment():
    env = {**os.environ, "DJANGO_SETTINGS_MODULE": "cutroom.settings", "PYTHONUNBUFFERED": "1"}
    if env.get("DATABASE_URL"):
        say(f"database from DATABASE_URL (…@{env['DATABASE_URL'].split('@')[-1]})")
    return env


def port_problem(host, port):
    """Why the web server could not listen on host:port, or None."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as exc:
            return f"cannot listen on {host}:{port} ({exc.strerror}); is Cutroom already " \
                   f"running? Choose another port: make up PORT={port + 1}"
    return None


def manage(env, *args):
    """Run a manage.py command in the foreground; exit with its code if it fails."""
    done = subprocess.run([sys.executable, "manage.py", *args], cwd=REPO, env=env)
    if done.returncode:
        say(f"`manage.py {' '.join(args)}` failed (exit code {done.returncode}); stopping")
        sys.exit(done.returncode)


class Child:
    """A child process in its own process group, logging to a file under var/log/."""

    def __init__(self, name, argv, env, log):
        self.name, self.argv, self.env, self.log = name, argv, env, log
        self.proc = None

    def start(self):
        self.log.parent.mkdir(parents=True, exist_ok=True)
        self.offset = self.log.stat().st_size if self.log.exists() else 0
        out = self.log.open("ab")
        self.proc = subprocess.Popen(
            self.argv, cwd=REPO, env=self.env, stdout=out, stderr=subprocess.STDOUT,
            # A process group of its own, so that Ctrl-C reaches up.py only; not a session of
            # its own: the kernel's autogroups share the CPU equally between sessions, which
            # would make the workers' and the bulk lane's nice values count for nothing.
            stdin=subprocess.DEVNULL, process_group=0,
        )
        out.close()
        return self

    def output(self):
        """What this run of the process has logged so far."""
        with self.log.open("rb") as handle:
            handle.seek(self.offset)
            return handle.read().decode("utf-8", "replace")

    def tail(self, lines=15):
        return "\n".join("    " + line for line in self.output().splitlines()[-lines:])

    def exited(self):
        return self.proc.poll()

    def stop(self):
        """Ask the main process to shut down; it stops its own children in order (a
        Celery worker lets its running job finish, gunicorn finishes its requests)."""
        if self.proc and self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)

    def kill(self):
        """SIGKILL the whole process group (main process and its children)."""
        try:
            os.killpg(self.proc.pid, signal.SIGKILL)
        except ProcessLookupError:
            pass

    def wait(self, timeout):
        try:
            self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            say(f"{self.name} did not stop within {timeout:.0f} s; killing it")
            self.kill()
            self.proc.wait(10)
        # Children orphaned by a main process that died first (e.g. a killed worker).
        self.kill()


# Each pool process runs one job on one core: BLAS threads of their own would oversubscribe
# the machine (measured: 0.34 s CPU per five-minute take with them, 0.22 s without).
SINGLE_THREADED = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def worker(env, logs, concurrency):
    argv = [
        "nice", "-n", str(WORKER_NICE),
        str(BIN / "celery"), "-A", "cutroom", "worker", "--loglevel", "INFO",
        "--concurrency", str(concurrency), "--hostname", "cutroom-up@%h",
        "--without-mingle", "--without-gossip",
    ]
    return Child("worker", argv, {**SINGLE_THREADED, **env}, logs / "worker.log")


def convert_worker(env, logs):
    """The worker of the FBX convert queue: Blender loaded once per pool process, which is
    replaced after some files (Blender's memory), each file under a time limit."""
    argv = [
        "nice", "-n", str(WORKER_NICE),
        str(BIN / "celery"), "-A", "cutroom", "worker", "--loglevel", "INFO",
        *convert_options(env), "--hostname", "cutroom-convert@%h",
        "--without-mingle", "--without-gossip",
    ]
    return Child("convert worker", argv, {**SINGLE_THREADED, **env, "CUTROOM_CONVERT_WORKER": "1"},
                 logs / "convert-worker.log")


def convert_options(env):
    """The convert worker's queue, slots (pool processes, one file each) and recycling."""
    return [
        "--queues", env.get("CUTROOM_CONVERT_QUEUE") or "convert",
        "--concurrency", env.get("CUTROOM_CONVERT_SLOTS") or str(CONVERT_SLOTS),
        "--max-tasks-per-child", "50",
    ]


def gunicorn(bind):
    """gunicorn's command line, as both web servers run it."""
    return [
        str(BIN / "gunicorn"), "cutroom.wsgi:application", "--bind", bind,
        "--workers", str(WEB_WORKERS), "--threads", str(WEB_THREADS), "--timeout", "120",
        "--access-logfile", "-", "--error-logfile", "-",
    ]


def web(env, logs, host, port):
    return Child("web server", gunicorn(f"{host}:{port}"), env, logs / "web.log")


def bulk_socket(env):
    """The bulk lane server's socket path ('' when CUTROOM_BULK_SOCKET is set empty: none)."""
    if "CUTROOM_BULK_SOCKET" in env:
        return env["CUTROOM_BULK_SOCKET"]
    return str(var_dir() / "run" / "bulk.sock")


def bulk_web(env, logs):
    """The bulk lane's server, or None; ``env`` (the web server's too) gets its socket."""
    path = env["CUTROOM_BULK_SOCKET"] = bulk_socket(env)
    if not path:
        return None
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    # Kept-alive connections from the web server, reused from request to request.
    argv = ["nice", "-n", str(BULK_NICE), *gunicorn(f"unix:{path}"), "--keep-alive", "75"]
    # It serves what it is handed, and hands nothing on.
    return Child("bulk lane server", argv, {**env, "CUTROOM_BULK_SOCKET": ""}, logs / "web-bulk.log")


def wait_ready(worker_child, web_child, url, timeout=90):
    """Block until the worker logged "ready" and the web server answers; False if one died."""
    deadline = time.monotonic() + timeout
    worker_up = web_up = False
    while time.monotonic() < deadline:
        for child in (worker_child, web_child):
            if child.exited() is not None:
                say(f"{child.name} exited during start-up (code {child.exited()}); "
                    f"end of {child.log}:\n{child.tail()}")
                return False
        worker_up = worker_up or " ready." in worker_child.output()
        web_up = web_up or answers(url + "login/")
        if worker_up and web_up:
            return True
        nap(0.2)
    say(f"not ready after {timeout} s (worker ready: {worker_up}, web ready: {web_up})")
    return False


def answers(url):
    try:
        with urllib.request.urlopen(url, timeout=2) as response:
            return response.status == 200
    except (urllib.error.URLError, OSError):
        return False


class Stop(Exception):
    """A stop signal arrived (its name); raised by ``nap``."""


# The stop signals received, oldest first.
STOPPING: list[str] = []


def on_signal(signum, frame):
    """Note the signal; the supervisor stops at its next ``nap``. Raising from here
    would land wherever the main thread happens to be: inside Django's first import
    (the watchdog's, just after the banner) Python wraps it into a RuntimeError, and an
    ``except Exception`` that keeps the watchdog going would swallow it."""
    STOPPING.append(signal.Signals(signum).name)


def nap(seconds):
    """Sleep ``seconds``; raise Stop as soon as a stop signal has arrived (within 0.1 s)."""
    deadline = time.monotonic() + seconds
    while not STOPPING:
        left = deadline - time.monotonic()
        if left <= 0:
            return
        time.sleep(min(0.1, left))
    raise Stop(STOPPING[0])


class Restarts:
    """Worker restarts, rate-limited rather than counted for life: the first
    RESTARTS_IN_WINDOW within RESTART_WINDOW seconds happen at once, each further one
    waits twice as long as the last (5 s, 10 s, ... up to LONGEST_PAUSE)."""

    def __init__(self, clock=time.monotonic):
        self.clock, self.times = clock, []

    def pause(self):
        """Record a restart; the seconds to wait before doing it."""
        now = self.clock()
        self.times = [t for t in self.times if now - t < RESTART_WINDOW] + [now]
        extra = len(self.times) - RESTARTS_IN_WINDOW
        return 0.0 if extra <= 0 else min(LONGEST_PAUSE, 5.0 * 2 ** (extra - 1))


class Watchdog:
    """The supervisor's own look at the jobs, independent of the worker it watches:
    every CUTROOM_SWEEP_SECONDS it requeues the jobs of dead pool processes and asks
    whether the worker is stuck (segmentation.services.health)."""

    def __init__(self, env, concurrency):
        os.environ.update(env)
        sys.path.insert(0, str(REPO))
        import django

        django.setup()
        from django.conf import settings

        self.concurrency, self.interval = concurrency, settings.CUTROOM_SWEEP_SECONDS
        self.grace = max(self.interval, settings.CUTROOM_STALL_SECONDS)
        self.restarted()

    def restarted(self):
        """A (re)started worker gets CUTROOM_STALL_SECONDS to take its first job."""
        self.due = time.monotonic() + self.grace
        self.resent = False

    def check(self):
        """Why the worker must be restarted, or None (also None until the next check).

        A job waiting while a worker process sits idle is first taken for a lost message:
        the waiting jobs are sent again and the worker gets CUTROOM_STALL_SECONDS to take
        them. Only a worker that does not is stuck (a healthy one was restarted again and
        again for a message no restart brings back)."""
        if time.monotonic() < self.due:
            return None
        self.due = time.monotonic() + self.interval
        from django.db import connection

        from segmentation.services import health

        try:
            stuck = health.look(self.concurrency)[1]
            if stuck is not None and not self.resent:
                self.resent, self.due = True, time.monotonic() + self.grace
                sent = health.resend_stalled()
                say(f"{stuck}; its message may have been lost: {sent} waiting job(s) sent "
                    f"again, and the worker is restarted only if it does not take them "
                    f"within {self.grace} s")
                return None
            if stuck is None:
                self.resent = False
            return stuck
        except Exception as exc:  # the database busy or gone: look again next time
            say(f"could not check the jobs ({type(exc).__name__}: {exc})")
            return None
        finally:
            connection.close()


def supervise(worker_child, web_child, watchdog, convert_child=None, bulk_child=None):
    """Watch the children until a signal arrives; returns the exit code for up.py.

    The web server keeps serving whatever happens to the worker; a worker that died or
    stalled is restarted (rate-limited by Restarts). A web server that died is restarted
    (rate-limited too: one that cannot start is not looped on fast); the workers go on
    meanwhile. A bulk lane server that died is restarted at once; meanwhile the web server
    serves those requests itself."""
    restarts, web_restarts = Restarts(), Restarts()
    while True:
        nap(0.5)
        for child in (convert_child, bulk_child):
            if child is not None and child.exited() is not None:
                restart_at_once(child)
        if web_child.exited() is not None:
            pause = web_restarts.pause()
            if pause:
                say(f"the web server died {RESTARTS_IN_WINDOW} times within "
                    f"{RESTART_WINDOW:.0f} s; waiting {pause:.0f} s before restarting it")
                nap(pause)
            restart_at_once(web_child)
        code = worker_child.exited()
        if code is not None:
            say(f"the worker died (exit code {code}); end of {worker_child.log}:\n"
                f"{worker_child.tail()}")
        else:
            stuck = watchdog.check()
            if stuck is None:
                continue
            say(f"the worker is stuck: {stuck}; end of {worker_child.log}:\n"
                f"{worker_child.tail()}")
        restart(worker_child, restarts.pause())
        watchdog.restarted()


def restart(worker_child, pause):
    worker_child.kill()  # the main process and the pool processes it left behind
    worker_child.proc.wait(10)
    requeue_abandoned(worker_child.env)
    if pause:
        say(f"the worker was restarted {RESTARTS_IN_WINDOW} times within "
            f"{RESTART_WINDOW:.0f} s; waiting {pause:.0f} s before restarting it "
            "(the web server keeps serving)")
        nap(pause)
    say("restarting the worker")
    worker_child.start()
    say(f"worker restarted, pid {worker_child.proc.pid}")


def restart_at_once(child):
    """Restart a child that died, at once: the web server (the service is unreachable
    until it is back), the convert worker (its conversion in hand is
    requeued by the periodic sweep once its claim is stale: sweeping now would also take
    the other worker's running jobs; Blender crashing or hanging on a file does not get
    here: that costs Blender's process only, and fails that capture) or the bulk lane
    server (meanwhile the web server serves its requests itself)."""
    say(f"the {child.name} died (exit code {child.exited()}); end of {child.log}:\n"
        f"{child.tail()}")
    child.kill()
    child.start()
    say(f"{child.name} restarted, pid {child.proc.pid}")


def requeue_abandoned(env):
    """Send the jobs of a worker that died (or was stopped, stuck) back to the queue, at once.

    The worker up.py runs is the only one, so every claim is abandoned and every message
    it held is free: sweeping with a claim timeout of 0 s requeues the claimed jobs (and
    fails a job that keeps killing workers, after CUTROOM_MAX_ATTEMPTS), and the SQLite
    broker's reservations are released. Redis gives unacknowledged jobs back by itself.
    """
    if not (env.get("CELERY_BROKER_URL") or "sqlite").startswith("sqlite"):
        return
    done = subprocess.run(
        [sys.executable, "manage.py", "sweep_claims", "--release-broker"], cwd=REPO,
        env={**env, "CUTROOM_CLAIM_TIMEOUT": "0", "CUTROOM_RESEND_AFTER": "0"},
        capture_output=True, text=True,
    )
    lines = (done.stdout + done.stderr).strip().splitlines()
    if done.returncode:
        say(f"could not requeue the dead worker's jobs (`manage.py sweep_claims` exit code "
            f"{done.returncode}): {lines[-1] if lines else 'no output'}")
    else:
        say(f"the dead worker's jobs: {lines[-1] if lines else 'no output'}")


def banner(url, worker_child, web_child, logs, demo):
    say(f"Cutroom is running at {url}")
    if demo:
        say("log in as annotator / cutroom-demo (also: reviewer, admin; same password)")
    say(f"web server pid {web_child.proc.pid}, worker pid {worker_child.proc.pid}; "
        f"logs in {logs}")
    say("press Ctrl-C to stop")


def main(argv=None):
    args = parse_args(argv)
    problem = port_problem(args.host, args.port)
    if problem:
        say(problem)
        return 2
    env = environment()
    # SQLite creates its file but not the folder it lives in.
    var_dir().mkdir(parents=True, exist_ok=True)
    logs = var_dir() / "log"
    manage(env, "migrate", "--noinput", "-v", "0")
    if not args.no_demo:
        manage(env, "demo", *(["--no-shared-data"] if args.no_shared_data else []))
    url = f"http://{args.host}:{args.port}/"
    worker_child = worker(env, logs, args.concurrency)
    convert_child = convert_worker(env, logs)
    bulk_child = bulk_web(env, logs)
    web_child = web(env, logs, args.host, args.port)
    children = [c for c in (web_child, bulk_child, worker_child, convert_child) if c]
    for stop_signal in STOP_SIGNALS:
        signal.signal(stop_signal, on_signal)
    code = 1
    try:
        worker_child.start()
        convert_child.start()
        if bulk_child:
            bulk_child.start()
        web_child.start()
        if wait_ready(worker_child, web_child, url):
            banner(url, worker_child, web_child, logs, not args.no_demo)
            say(f"FBX convert worker pid {convert_child.proc.pid} (Blender), log "
                f"{convert_child.log}")
            if bulk_child:
                say(f"bulk lane server pid {bulk_child.proc.pid} (requests about long takes, "
                    f"nice {BULK_NICE}), log {bulk_child.log}")
            code = supervise(worker_child, web_child, Watchdog(env, args.concurrency),
                             convert_child, bulk_child)
    except Stop as stop:
        say(f"{stop} received; stopping the web server and the worker")
        code = 0
    finally:
        for stop_signal in STOP_SIGNALS:
            signal.signal(stop_signal, signal.SIG_IGN)
        for child in children:
            child.stop()
        for child in children:
            if child.proc:
                child.wait(30)
    say("stopped")
    return code


if __name__ == "__main__":
    sys.exit(main())
