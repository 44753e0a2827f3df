"""Library query benchmark on PostgreSQL: 100,000 segments, the segment list API.

Creates a scratch database, migrates it, fills it with a seeded library (4 projects,
400 captures, 20 annotators, 10 labels per project, a gold version on one capture in ten),
then times ``GET /api/segments/`` (the real view: role filter, query-string filters,
count and one page) for typical queries, and prints one row per query: rows matched,
median and 90th-percentile milliseconds, SQL queries per request, and the indexes
PostgreSQL's plan uses for the page query. The scratch database is dropped at the end.

    DATABASE_ADMIN_URL=postgres://postgres@127.0.0.1:5432/postgres \\
        .venv/bin/python benchmarks/library_query.py [--segments 100000] [--repeat 15]
"""

import argparse
import os
import re
import statistics
import time

from harness import drop_database, scratch_database, start_django

N_DESCRIBED = 20000
LABELS = ["walk", "run", "jump", "punch", "kick", "squat", "wave", "turn", "sit", "idle"]


def populate(n_segments, seed=6):
    """A seeded library; returns the personas and ids the queries use."""
    import numpy as np
    from django.contrib.auth import get_user_model
    from django.db import connection

    from segmentation.models import Capture, Label, Membership, Project
    from segmentation.models_library import LibrarySegment

    rng = np.random.default_rng(seed)
    users = get_user_model().objects
    reviewer = users.create_user("rachel")
    annotators = [users.create_user(f"annotator{i:02d}") for i in range(20)]
    projects = [Project.objects.create(name=f"Studio {i}") for i in range(4)]
    for p in projects:
        Membership.objects.create(project=p, user=reviewer, role="reviewer")
        Membership.objects.bulk_create(Membership(project=p, user=u, role="annotator") for u in annotators)
    labels = {p.pk: Label.objects.bulk_create(Label(project=p, name=n) for n in LABELS) for p in projects}
    captures = Capture.objects.bulk_create(
        Capture(project=projects[i % 4], name=f"take_{i:04d}.bvh", checksum=f"c{i}", format="bvh",
                status="ready", fps=120.0, n_frames=20000, original=f"captures/take_{i}.bvh")
        for i in range(400)
    )
    gold_captures = {c.pk for c in captures[::10]}
    rows, described = [], 0
    for k in range(n_segments):
        capture = captures[int(rng.integers(len(captures)))]
        is_gold = capture.pk in gold_captures and rng.random() < 0.25
        label = labels[capture.project_id][int(rng.integers(len(LABELS)))]
        start = int(rng.integers(0, 19000))
        length = int(rng.integers(30, 1000))
        # Project 0's first segments carry motion descriptors for the similar-clip search.
        with_descriptor = capture.project_id == projects[0].pk and described < N_DESCRIBED
        described += with_descriptor
        descriptor = rng.normal(size=(35, 35)).astype("<f4") if with_descriptor else None
        rows.append(LibrarySegment(
            descriptor=descriptor.tobytes() if with_descriptor else None,
            descriptor_shape=[35, 35] if with_descriptor else None,
            profile=descriptor[:3].tobytes() if with_descriptor else None,
            project_id=capture.project_id, capture=capture,
            annotator=None if is_gold else annotators[int(rng.integers(20))], is_gold=is_gold,
            superseded=not is_gold and capture.pk in gold_captures, label=label,
            label_name=label.name, start=start, stop=start + length, duration=length / 120.0,
            agreement=float(rng.beta(5, 2)) if rng.random() < 0.8 else None))
        if len(rows) == 5000 or k == n_segments - 1:
            LibrarySegment.objects.bulk_create(rows)
            rows = []
    with connection.cursor() as cursor:
        cursor.execute("ANALYZE")
    return {"reviewer": reviewer, "annotator": annotators[3], "project": projects[0],
            "capture": captures[0], "annotator_id": annotators[7].pk}


def queries(ctx):
    p = ctx["project"].pk
    return [
        ("reviewer", "first page, all projects", ""),
        ("reviewer", "project", f"project={p}"),
        ("reviewer", "project + label", f"project={p}&label=walk"),
        ("reviewer", "label + duration 1-3 s", f"project={p}&label=kick&min_duration=1&max_duration=3"),
        ("reviewer", "annotator", f"project={p}&annotator={ctx['annotator_id']}"),
        ("reviewer", "capture", f"capture={ctx['capture'].pk}"),
        ("reviewer", "agreement >= 0.9, best first", f"project={p}&min_agreement=0.9&ordering=-agreement"),
        ("reviewer", "gold only", f"project={p}&gold=true"),
        ("reviewer", "longest first", f"project={p}&ordering=-duration"),
        ("reviewer", "page 100 of project", f"project={p}&page=100"),
        ("annotator", "own + gold", ""),
        ("annotator", "own + gold, label", "label=squat"),
    ]


PLAN_INDEX = re.compile(r"(?:Index(?: Only)? Scan(?: Backward)? using|Bitmap Index Scan on) (\w+)")


def plan_of(sql):
    from django.db import connection

    with connection.cursor() as cursor:
        cursor.execute("EXPLAIN " + sql)
        text = "\n".join(row[0] for row in cursor.fetchall())
    used = sorted(set(PLAN_INDEX.findall(text)))
    return ", ".join(used) + (" + seq scan" if "Seq Scan" in text else "") or "seq scan"


def run_query(user, query, repeat):
    from django.db import connection
    from django.test.utils import CaptureQueriesContext
    from rest_framework.test import APIRequestFactory, force_authenticate

    from segmentation.api.library import SegmentListView

    view = SegmentListView.as_view()
    factory = APIRequestFactory()
    times = []
    for i in range(repeat + 1):
        request = factory.get(f"/api/segments/?{query}")
        force_authenticate(request, user=user)
        with CaptureQueriesContext(connection) as captured:
            started = time.perf_counter()
            response = view(request)
            response.render()
            elapsed = time.perf_counter() - started
        if response.status_code != 200:
            raise SystemExit(f"{query}: HTTP {response.status_code} {response.content[:200]!r}")
        if i:  # the first run warms caches
            times.append(elapsed * 1000)
    return response.data["count"], times, len(captured), plan_of(captured[-1]["sql"])


def similar_table(ctx, repeat):
    """``GET /api/segments/{id}/similar/?k=10`` over the described segments of project 0."""
    from rest_framework.test import APIRequestFactory, force_authenticate

    from segmentation.api.library import SimilarView
    from segmentation.models_library import LibrarySegment

    query = LibrarySegment.objects.filter(descriptor__isnull=False).order_by("id").first()
    view, factory, times = SimilarView.as_view(), APIRequestFactory(), []
    for i in range(min(repeat, 5) + 1):
        request = factory.get(f"/api/segments/{query.pk}/similar/?k=10")
        force_authenticate(request, user=ctx["reviewer"])
        started = time.perf_counter()
        response = view(request, pk=query.pk)
        response.render()
        if i:
            times.append((time.perf_counter() - started) * 1000)
    assert response.status_code == 200, response.content[:200]
    print(f"similar clips: pool of {N_DESCRIBED:,} described segments (35 x 35 float32), k=10: "
          f"median {statistics.median(times):.0f} ms over {len(times)} runs")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=100_000)
    parser.add_argument("--repeat", type=int, default=15)
    parser.add_argument("--admin-url", default=os.environ.get(
        "DATABASE_ADMIN_URL", "postgres://postgres@127.0.0.1:5432/postgres"))
    args = parser.parse_args()
    name = f"cutroom_bench_library_{os.getpid()}"
    url = scratch_database(args.admin_url, name)
    try:
        started = time.perf_counter()
        start_django(DATABASE_URL=url)
        ctx = populate(args.segments)
        print(f"scratch database {name}: {args.segments:,} segments loaded in "
              f"{time.perf_counter() - started:.1f} s (PostgreSQL, {args.repeat} timed runs each)\n")
        header = f"{'who':<10} {'query':<32} {'matched':>8} {'median ms':>10} {'p90 ms':>8} {'SQL':>4}  page plan uses"
        print(header)
        print("-" * len(header))
        for who, title, query in queries(ctx):
            user = ctx["reviewer"] if who == "reviewer" else ctx["annotator"]
            count, times, n_sql, plan = run_query(user, query, args.repeat)
            p90 = statistics.quantiles(times, n=10)[-1]
            print(f"{who:<10} {title:<32} {count:>8,} {statistics.median(times):>10.1f} "
                  f"{p90:>8.1f} {n_sql:>4}  {plan}")
        print()
        similar_table(ctx, args.repeat)
    finally:
        from django.db import connections

        connections.close_all()
        drop_database(args.admin_url, name)
        print(f"\nscratch database {name} dropped")


if __name__ == "__main__":
    main()
