"""What the service benchmarks share: a scratch PostgreSQL database, Django started on
a chosen environment, stopping a child process group, busy processes for a known load,
and `make up`'s own script."""

import contextlib
import functools
import importlib.util
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path
from urllib.parse import urlparse, urlunparse

REPO = Path(__file__).resolve().parents[1]


def up_script():
    """``scripts/up.py`` as a module (it is a script, not part of a package), so a benchmark
    starts processes the way `make up` does."""
    spec = importlib.util.spec_from_file_location("up", REPO / "scripts" / "up.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def database_url(server, name):
    """``server`` (any PostgreSQL URL; its database part is ignored) pointed at ``name``."""
    return urlunparse(urlparse(server)._replace(path=f"/{name}"))


def scratch_database(server, name):
    """Create database ``name`` (dropping a leftover of the same name); returns its URL."""
    _admin(server, f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)', f'CREATE DATABASE "{name}"')
    return database_url(server, name)


def drop_database(server, name):
    _admin(server, f'DROP DATABASE IF EXISTS "{name}" WITH (FORCE)')


def _admin(server, *statements):
    import psycopg

    with psycopg.connect(database_url(server, "postgres"), autocommit=True) as conn:
        for statement in statements:
            conn.execute(statement)


def start_django(unset=(), **env):
    """Set up Django in this process on ``env`` (minus the ``unset`` variables) and
    migrate its database."""
    for name in unset:
        os.environ.pop(name, None)
    os.environ.update(env)
    os.environ.setdefault("DJANGO_SETTINGS_MODULE", "cutroom.settings")
    if str(REPO) not in sys.path:
        sys.path.insert(0, str(REPO))
    import django

    django.setup()
    from django.core.management import call_command

    call_command("migrate", verbosity=0)


def in_scratch_installation(prefix, run, args):
    """``run(args, var)`` with Django set up on the embedded default in a scratch ``var``
    folder (removed afterwards) and numpy on one core: the service as one worker process
    runs it, whatever the caller's environment points at."""
    # numpy is imported with Django below: set before, it must not fan out to other cores.
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, "1")
    var = Path(tempfile.mkdtemp(prefix=prefix))
    try:
        start_django(unset=("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT",
                            "CELERY_BROKER_DIR"), CUTROOM_VAR_DIR=str(var))
        run(args, var)
    finally:
        shutil.rmtree(var, ignore_errors=True)


def stop(proc):
    """SIGTERM, then the whole process group killed if it is not gone within 30 s."""
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(30)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait(10)


@contextlib.contextmanager
def busy(n, nice=0):
    """``n`` processes spinning on a core (``while True: pass``) for the length of the
    block, killed at its end: a benchmark's times under a load one can state and repeat.

    They run at nice ``nice`` whatever the caller's niceness (when it may lower it): 0, the
    default, competes with the benchmark as ordinary requests' neighbours would; 10 is
    the service's own workers, which ``scripts/up.py`` runs at nice 10.
    """
    spinners = [subprocess.Popen([sys.executable, "-c", "while True: pass"],
                                 preexec_fn=functools.partial(_set_nice, nice)) for _ in range(n)]
    try:
        yield spinners
    finally:
        for proc in spinners:
            proc.kill()
        for proc in spinners:
            proc.wait()


def _set_nice(nice):
    with contextlib.suppress(PermissionError):
        os.setpriority(os.PRIO_PROCESS, 0, nice)


def mapped_rss(name):
    """kB of the memory maps of files whose path ends with ``name`` resident in this
    process: (Rss, Pss), from ``/proc/self/smaps``."""
    rss = pss = 0
    inside = False
    with open("/proc/self/smaps") as fh:
        for line in fh:
            if "-" in line.split(" ", 1)[0]:
                inside = line.rstrip().endswith(name)
            elif inside and line.startswith("Rss:"):
                rss += int(line.split()[1])
            elif inside and line.startswith("Pss:"):
                pss += int(line.split()[1])
    return rss, pss


def load():
    """The load average (1, 5, 15 min) as a benchmark prints it: "1.2, 0.8, 0.5"."""
    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


def reclaim():
    """The kernel's proactive reclaim, as a benchmark prints it: DAMON schemes that page out
    memory idle for a while take file pages (the index files, PostgreSQL's files) out of
    the page cache whatever memory is free, so a later read of them goes to the disk."""
    root = Path("/sys/kernel/mm/damon/admin/kdamonds")
    found = []
    for kdamond in sorted(root.glob("[0-9]*")):
        try:
            if (kdamond / "state").read_text().strip() != "on":
                continue
            for context in sorted((kdamond / "contexts").glob("[0-9]*")):
                aggr = int((context / "monitoring_attrs/intervals/aggr_us").read_text())
                for scheme in sorted((context / "schemes").glob("[0-9]*")):
                    action = (scheme / "action").read_text().strip()
                    age = int((scheme / "access_pattern/age/min").read_text())
                    if action == "pageout":
                        found.append(f"pages idle >= {age * aggr / 1e6:.0f} s paged out")
        except (OSError, ValueError):
            continue
    return f"proactive reclaim (DAMON): {', '.join(found)}" if found else "no proactive reclaim"
