"""The service started for a benchmark: a scratch PostgreSQL database, Django set up on
a chosen environment, a scratch installation of the embedded default, stopping a child
process group, and `make up`'s own script."""

import importlib.util
import os
import shutil
import signal
import subprocess
import tempfile
from pathlib import Path
from urllib.parse import urlparse, urlunparse

from benchmarks.harness import REPO


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
