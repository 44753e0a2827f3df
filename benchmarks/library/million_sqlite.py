"""The seeded library of ``million.py`` on the embedded default (SQLite), built once and reused.

Same data as the PostgreSQL one (same seed, same distributions: project "Archive" with ``n``
described segments, three projects of 20,000, 20 annotators, a reviewer, 10 labels, gold on
one capture in ten, agreement on 80 %), written with plain ``INSERT``s into a database file
migrated as `make up` migrates it, in ``benchmarks/out/million_<n>_s<seed>_sqlite/``
(git-ignored). A marker table says the build finished; deleting the folder starts again. No
``ANALYZE`` is run: an installation on the embedded default has no planner statistics
unless the product gathers them itself, so the benchmark reads the file as one would.
"""

import sqlite3
import time

import numpy as np

from benchmarks.harness import OUT
from benchmarks.harness.service import start_django
from benchmarks.library import million


def path_of(n, seed):
    folder = OUT / f"million_{n}_s{seed}_sqlite"
    folder.mkdir(parents=True, exist_ok=True)
    return folder / "library.sqlite3"


def complete(path):
    if not path.exists():
        return False
    with sqlite3.connect(path) as conn:
        return bool(conn.execute("SELECT 1 FROM sqlite_master WHERE name = 'bench_complete'")
                    .fetchone())


def connect(n, seed, rebuild=False):
    """Start Django on the cached SQLite million database, building it first when needed.
    Returns the database file's path."""
    path = path_of(n, seed)
    build = rebuild or not complete(path)
    if build:
        for suffix in ("", "-wal", "-shm"):
            path.with_name(path.name + suffix).unlink(missing_ok=True)
    start_django(unset=("DATABASE_URL",), DATABASE_URL=f"sqlite:///{path}")
    if build:
        populate(n, seed)
    return path


def populate(n, seed):
    from django.contrib.auth import get_user_model
    from django.db import connection

    from segmentation.models import Capture, Label, Membership, Project

    rng = np.random.default_rng(seed)
    started = time.perf_counter()
    owners, bases = million.base_descriptors(rng)
    print(f"[million] {len(bases)} base descriptors in {time.perf_counter() - started:.0f} s")
    users = get_user_model().objects
    users.create_user("rachel")
    annotators = [users.create_user(f"annotator{i:02d}") for i in range(20)]
    projects = [Project.objects.create(name="Archive" if i == 0 else f"Studio {i}")
                for i in range(4)]
    reviewer = users.get(username="rachel")
    for p in projects:
        Membership.objects.create(project=p, user=reviewer, role="reviewer")
        Membership.objects.bulk_create(Membership(project=p, user=u, role="annotator")
                                       for u in annotators)
    labels = {p.pk: Label.objects.bulk_create(Label(project=p, name=x) for x in million.LABELS)
              for p in projects}
    for p, size in zip(projects, [n] + [million.SMALL_PROJECT] * 3, strict=True):
        captures = Capture.objects.bulk_create(
            Capture(project=p, name=f"take_{p.pk}_{i:05d}.bvh", checksum=f"c{p.pk}_{i}",
                    format="bvh", status="ready", fps=120.0, n_frames=200_000,
                    original=f"captures/take_{p.pk}_{i}.bvh")
            for i in range(max(10, size // 250)))
        cap_ids = np.array([c.pk for c in captures])
        gold = set(cap_ids[::10].tolist())
        label_ids = [(x.pk, x.name) for x in labels[p.pk]]
        for first in range(0, size, 50_000):
            count = min(50_000, size - first)
            desc = million.blend(rng, owners, bases, count)
            _insert_rows(connection, rng, p.pk, cap_ids, gold, label_ids, annotators, desc)
            print(f"[million] project {p.name}: {first + count:,}/{size:,} rows "
                  f"({time.perf_counter() - started:.0f} s)", flush=True)
    with connection.cursor() as cursor:
        cursor.execute("CREATE TABLE bench_complete (n integer, seed integer)")
        cursor.execute("INSERT INTO bench_complete VALUES (%s, %s)", [n, seed])
    print(f"[million] built in {time.perf_counter() - started:.0f} s")


def _insert_rows(connection, rng, project_id, cap_ids, gold, label_ids, annotators, desc):
    """The rows ``million._copy_rows`` copies into PostgreSQL, drawn the same way."""
    from django.db import transaction
    from django.utils import timezone

    rows = list(million.segment_rows(rng, project_id, cap_ids, gold, label_ids, annotators,
                                     desc, timezone.now().isoformat(sep=" ")))
    columns = ", ".join(million.COLUMNS)
    marks = ", ".join(["%s"] * len(million.COLUMNS))
    with transaction.atomic(), connection.cursor() as cursor:
        cursor.executemany(f"INSERT INTO segmentation_librarysegment ({columns}) "
                           f"VALUES ({marks})", rows)

