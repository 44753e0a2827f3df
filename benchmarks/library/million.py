"""A seeded library of a million described segments on PostgreSQL, built once and reused.

Shared by ``listing`` and ``similar_search``, which build it on first use. The database
``cutroom_bench_million_<n>_s<seed>`` is kept after a run (a marker table says it is
complete), so the slow build happens once per machine and revision (a revision compared
against has its own: ``harness.kept_name``); dropping it makes the next run build it anew.
Next to it, ``benchmarks/out/million_<n>_s<seed>/`` (git-ignored) keeps the segment ids
and profiles as ``.npy`` for the exact-search oracle.

The data: project 0 ("Archive") holds ``n`` segments, projects 1-3 hold 20,000 each; 20
annotators, a reviewer, 10 labels, a gold version on one capture in ten (their annotator
segments superseded), agreement on 80 %. Every segment carries a motion descriptor made
from real ones: descriptors of random spans (0.5-4 s) of the CMU takes in
``shared/data`` (``$CUTROOM_BENCH_DATA``) and of ``motionlib.synth`` takes, each library descriptor a random
blend of two spans of the same take plus noise of 3 % of each feature's spread, so the
library has the clustered structure of real motion rather than uniform noise (which no
vector index is built for and no studio has).
"""

import os
import time

import numpy as np

from benchmarks.harness import OUT, kept_name
from benchmarks.harness.service import database_url

SMALL_PROJECT = 20_000
LABELS = ["walk", "run", "jump", "punch", "kick", "squat", "wave", "turn", "sit", "idle"]
CMU = [("13_29", "13"), ("13_30", "13"), ("86_01", "86"), ("02_07", "02"), ("06_02", "06"),
       ("13_17", "13"), ("93_04", "93")]


def name_of(n, seed):
    return kept_name(f"cutroom_bench_million_{n}_s{seed}")


def out_dir(n, seed):
    path = OUT / f"million_{n}_s{seed}"
    path.mkdir(parents=True, exist_ok=True)
    return path


def base_descriptors(rng, per_take=400):
    """(n_bases,) take index and (n_bases, 35, 35) descriptors of random spans of real and
    synthetic takes."""
    import motionlib
    from benchmarks.harness import data_dir
    from motionlib import similarity, synth

    takes, data = [], data_dir()
    for seq, subject in CMU:
        path = data / "cmu" / "amc" / f"{seq}.amc"
        if path.exists():
            takes.append(motionlib.read(path, asf=data / "cmu" / "asf" / f"{subject}.asf"))
    for i in range(4):
        takes.append(synth.generate(seed=100 + i, duration=120)[0])
    owners, descs = [], []
    for t, take in enumerate(takes):
        positions = motionlib.forward_kinematics(take)
        joints = motionlib.canonical_indices(take)
        scale = similarity.body_scale(positions, joints)
        for _ in range(per_take):
            length = int(rng.uniform(0.5, 4.0) * take.fps)
            start = int(rng.integers(0, max(1, len(positions) - length)))
            descs.append(similarity.segment_descriptor(positions, joints, start, start + length,
                                                       fps=take.fps, scale=scale))
            owners.append(t)
    return np.array(owners), np.stack(descs)


def blend(rng, owners, bases, count):
    """``count`` descriptors, each between two bases of one take, plus a little noise."""
    spread = bases.reshape(len(bases), -1).std(axis=0).reshape(bases.shape[1:])
    a = rng.integers(len(bases), size=count)
    same = [np.flatnonzero(owners == owners[i]) for i in range(len(bases))]
    b = np.array([rng.choice(same[i]) for i in a])
    t = rng.uniform(0, 0.5, size=(count, 1, 1)).astype(np.float32)
    noise = rng.normal(size=(count, *bases.shape[1:])).astype(np.float32) * (0.03 * spread)
    return (bases[a] * (1 - t) + bases[b] * t + noise).astype("<f4")


def exists(admin_url, name):
    import psycopg

    with psycopg.connect(database_url(admin_url, "postgres"), autocommit=True) as conn:
        if not conn.execute("SELECT 1 FROM pg_database WHERE datname = %s", (name,)).fetchone():
            return False
    with psycopg.connect(database_url(admin_url, name), autocommit=True) as conn:
        return bool(conn.execute("SELECT to_regclass('bench_complete')").fetchone()[0])


def populate(n, seed):
    """Fill the (migrated, empty) database Django is connected to."""
    from django.contrib.auth import get_user_model
    from django.db import connection

    from segmentation.models import Capture, Label, Membership, Project

    rng = np.random.default_rng(seed)
    started = time.perf_counter()
    owners, bases = base_descriptors(rng)
    print(f"[million] {len(bases)} base descriptors in {time.perf_counter() - started:.0f} s")
    users = get_user_model().objects
    reviewer = users.create_user("rachel")
    annotators = [users.create_user(f"annotator{i:02d}") for i in range(20)]
    projects = [Project.objects.create(name="Archive" if i == 0 else f"Studio {i}")
                for i in range(4)]
    for p in projects:
        Membership.objects.create(project=p, user=reviewer, role="reviewer")
        Membership.objects.bulk_create(Membership(project=p, user=u, role="annotator")
                                       for u in annotators)
    labels = {p.pk: Label.objects.bulk_create(Label(project=p, name=x) for x in LABELS)
              for p in projects}
    sizes = [n, SMALL_PROJECT, SMALL_PROJECT, SMALL_PROJECT]
    ids, profiles = [], []
    for p, size in zip(projects, sizes, strict=True):
        n_captures = max(10, size // 250)
        captures = Capture.objects.bulk_create(
            Capture(project=p, name=f"take_{p.pk}_{i:05d}.bvh", checksum=f"c{p.pk}_{i}",
                    format="bvh", status="ready", fps=120.0, n_frames=200_000,
                    original=f"captures/take_{p.pk}_{i}.bvh") for i in range(n_captures))
        cap_ids = np.array([c.pk for c in captures])
        gold = set(cap_ids[::10].tolist())
        label_ids = [(x.pk, x.name) for x in labels[p.pk]]
        for first in range(0, size, 50_000):
            count = min(50_000, size - first)
            desc = blend(rng, owners, bases, count)
            _copy_rows(connection, rng, p.pk, cap_ids, gold, label_ids, annotators, desc)
            print(f"[million] project {p.name}: {first + count:,}/{size:,} rows "
                  f"({time.perf_counter() - started:.0f} s)", flush=True)
        if p == projects[0]:
            with connection.cursor() as cursor:
                cursor.execute("SELECT id, profile FROM segmentation_librarysegment "
                               "WHERE project_id = %s ORDER BY id", [p.pk])
                for pk, blob in cursor.fetchall():
                    ids.append(pk)
                    profiles.append(np.frombuffer(bytes(blob), dtype="<f4"))
    with connection.cursor() as cursor:
        # What autovacuum does after a large load, done now: statistics, and the
        # visibility map that index-only scans need.
        cursor.execute("VACUUM ANALYZE segmentation_librarysegment")
        cursor.execute("ANALYZE")
        cursor.execute("CREATE TABLE bench_complete (n integer, seed integer)")
        cursor.execute("INSERT INTO bench_complete VALUES (%s, %s)", [n, seed])
    out = out_dir(n, seed)
    np.save(out / "ids.npy", np.array(ids, dtype=np.int64))
    np.save(out / "profiles.npy", np.stack(profiles))
    print(f"[million] built in {time.perf_counter() - started:.0f} s")


COLUMNS = ("project_id", "capture_id", "annotator_id", "is_gold", "superseded", "label_id",
           "start", "stop", "duration", "agreement", "descriptor", "descriptor_shape", "profile",
           "created_at")


def _copy_rows(connection, rng, project_id, cap_ids, gold, label_ids, annotators, desc):
    from django.utils import timezone

    rows = segment_rows(rng, project_id, cap_ids, gold, label_ids, annotators, desc,
                        timezone.now())
    with connection.cursor() as cursor:
        with cursor.cursor.copy(f"COPY segmentation_librarysegment ({', '.join(COLUMNS)}) "
                                "FROM STDIN") as copy:
            for row in rows:
                copy.write_row(row)


def segment_rows(rng, project_id, cap_ids, gold, label_ids, annotators, desc, now):
    """The library rows (``COLUMNS``) of one project's segments, one per descriptor: their
    capture, label, span, annotator or gold and agreement drawn from ``rng`` (the same
    draws, in the same order, whichever database they go to)."""
    count = len(desc)
    caps = cap_ids[rng.integers(len(cap_ids), size=count)]
    labs = rng.integers(len(label_ids), size=count)
    starts = rng.integers(0, 190_000, size=count)
    lengths = rng.integers(30, 1000, size=count)
    anns = rng.integers(len(annotators), size=count)
    gold_draw = rng.random(count)
    agree = rng.beta(5, 2, size=count)
    has_agree = rng.random(count) < 0.8
    for i in range(count):
        cap = int(caps[i])
        is_gold = bool(cap in gold and gold_draw[i] < 0.25)
        label_id, _ = label_ids[labs[i]]
        yield (
            project_id, cap, None if is_gold else annotators[anns[i]].pk, is_gold,
            not is_gold and cap in gold, label_id, int(starts[i]),
            int(starts[i] + lengths[i]), float(lengths[i]) / 120.0,
            float(agree[i]) if has_agree[i] else None, desc[i].tobytes(), "[35, 35]",
            desc[i, :3].tobytes(), now)


def connect(admin_url, n, seed, rebuild=False):
    """Start Django on the cached million database, building it first when needed.

    Returns the database name and the folder of cached arrays.
    """
    from harness import drop_database, scratch_database, start_django

    name = name_of(n, seed)
    out = out_dir(n, seed)
    if rebuild or not exists(admin_url, name) or not (out / "profiles.npy").exists():
        scratch_database(admin_url, name)
        start_django(DATABASE_URL=database_url(admin_url, name))
        try:
            populate(n, seed)
        except BaseException:
            from django.db import connections

            connections.close_all()
            drop_database(admin_url, name)
            raise
    else:
        start_django(DATABASE_URL=database_url(admin_url, name))
    return name, out


def personas():
    from django.contrib.auth import get_user_model

    from segmentation.models import Project

    users = get_user_model().objects
    return {"reviewer": users.get(username="rachel"), "annotator": users.get(username="annotator03"),
            "annotator_id": users.get(username="annotator07").pk,
            "project": Project.objects.get(name="Archive")}


def default_admin_url():
    return os.environ.get("DATABASE_ADMIN_URL", "postgres://postgres@127.0.0.1:5432/postgres")

