"""Library list benchmark: a million segments, first and 100th page.

Uses the seeded million-segment library (``million_sqlite`` on the embedded default,
SQLite, by default; ``--postgres`` for ``million``'s PostgreSQL one; each built on first
use, then kept) and times ``GET /api/segments/`` (the real view: role filter, query-string
filters, one page of 50 with its count) for typical filters and orders, each on page 1
and page 100. One row per query and page: rows matched (``10,000+`` = capped), median and
95th-percentile milliseconds, the median CPU time per request in this process (``CPU``:
SQLite runs in it, PostgreSQL does not; on a shared machine it is the steadier figure),
its SQL queries per request, a digest of the page's JSON (``page``: two runs whose digests
agree returned the same segments, fields byte for byte), and the indexes the database's
plan uses for its page query (``+ sort`` when it sorts the matches, ``+ table scan`` when
it reads the table). The process is set up as the web server's are (``cutroom/wsgi.py``,
which freezes the objects loaded at start out of the collector's way), and each series
starts with a collection.

The list as it was before the SQLite work is the product of ``51c396e^``: ``python -m
benchmarks library-list --against 51c396e^`` times it from a worktree of that revision,
on a library of its own built by its own migrations, then this checkout's, in one run.

``--busy N`` adds N processes that spin on a core (nice 0) while the queries are timed,
killed at the end, so that a figure "at load N" comes from one command; the load average
is printed after they have run 30 s and at the end.

    python -m benchmarks library-list [-- --segments 1000000 --repeat 20 --busy 3]
    DATABASE_ADMIN_URL=postgres://postgres@127.0.0.1:5432/postgres \\
        python -m benchmarks library-list-postgres
"""

import argparse
import gc
import hashlib
import json
import os
import platform
import re
import time

from benchmarks.harness.machine import busy, load
from benchmarks.harness.timing import Table, median, p95, timed
from benchmarks.library import million, million_sqlite


def queries(ctx):
    p = ctx["project"].pk
    return [
        ("reviewer", "all projects", ""),
        ("reviewer", "project", f"project={p}"),
        ("reviewer", "project + label", f"project={p}&label=walk"),
        ("reviewer", "label + duration 1-3 s", f"project={p}&label=kick&min_duration=1&max_duration=3"),
        ("reviewer", "annotator", f"project={p}&annotator={ctx['annotator_id']}"),
        ("reviewer", "capture", f"capture={ctx['capture']}"),
        ("reviewer", "agreement >= 0.9, best first", f"project={p}&min_agreement=0.9&ordering=-agreement"),
        ("reviewer", "gold only", f"project={p}&gold=true"),
        ("reviewer", "longest first", f"project={p}&ordering=-duration"),
        ("reviewer", "by label", f"project={p}&ordering=label"),
        ("reviewer", "by capture", f"project={p}&ordering=capture"),
        ("annotator", "own + gold", ""),
        ("annotator", "own + gold, label", "label=squat"),
    ]


PLAN_INDEX = re.compile(r"(?:Index(?: Only)? Scan(?: Backward)? using|Bitmap Index Scan on"
                        r"|USING (?:COVERING )?INDEX) (\w+)")


def plan_of(sql):
    """The indexes the database's plan for ``sql`` uses, and whether it scans or sorts."""
    from django.db import connection

    sqlite = connection.vendor == "sqlite"
    with connection.cursor() as cursor:
        cursor.execute(("EXPLAIN QUERY PLAN " if sqlite else "EXPLAIN ") + sql)
        text = "\n".join(str(row[-1] if sqlite else row[0]) for row in cursor.fetchall())
    used = sorted(set(PLAN_INDEX.findall(text)))
    scan = "Seq Scan" in text or re.search(r"SCAN \w+(?! USING)", text) is not None
    sort = "TEMP B-TREE" in text
    return (", ".join(used) + (" + table scan" if scan else "")
            + (" + sort" if sort else "")) or "table scan"


def run_query(user, query, repeat, view_class):
    """(matched, ms, CPU ms, SQL queries, page plan, page digest) of ``repeat`` timed
    requests for ``query`` after one that warms the caches."""
    from django.db import connection
    from django.test.utils import CaptureQueriesContext
    from rest_framework.test import APIRequestFactory, force_authenticate

    view = view_class.as_view()
    factory = APIRequestFactory()
    # Another series' garbage is not this one's to collect: a server process runs one list.
    gc.collect()

    def request():
        req = factory.get(f"/api/segments/?{query}")
        force_authenticate(req, user=user)
        with CaptureQueriesContext(connection) as captured:
            response = view(req)
            response.render()
        return response, captured

    times, cpu, (response, captured) = timed(request, repeat)
    if response.status_code == 404:
        return "no page", [float("nan")], [float("nan")], 0, "(fewer than 100 pages)", "-"
    if response.status_code != 200:
        raise SystemExit(f"{query}: HTTP {response.status_code} {response.content[:200]!r}")
    pages = [q["sql"] for q in captured if "LIMIT" in q["sql"] and "COUNT" not in q["sql"]]
    count = f"{response.data['count']:,}" + ("+" if response.data.get("count_capped") else "")
    digest = hashlib.sha1(json.dumps(response.data["results"]).encode()).hexdigest()[:8]
    return count, times, cpu, len(captured), plan_of(pages[0]) if pages else "-", digest


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--postgres", action="store_true",
                        help="PostgreSQL (million) instead of the embedded default")
    parser.add_argument("--busy", type=int, default=0,
                        help="processes spinning on a core while the queries are timed")
    parser.add_argument("--admin-url", default=million.default_admin_url())
    args = parser.parse_args()
    if args.postgres:
        name, _ = million.connect(args.admin_url, args.segments, args.seed)
        where = f"PostgreSQL database {name}"
    else:
        where = f"SQLite file {million_sqlite.connect(args.segments, args.seed).name}"
    ctx = million.personas()
    # cutroom.wsgi sets this process up as a web server process is (the URLconf loaded, then
    # gc.freeze()); else a full collection rescans every long-lived object inside a timed
    # request, which the server does not.
    import cutroom.wsgi  # noqa: F401
    from segmentation.api.segments import SegmentListView
    from segmentation.models import LibrarySegment

    ctx["capture"] = (LibrarySegment.objects.filter(project=ctx["project"]).order_by("id")
                      .values_list("capture_id", flat=True).first())
    print(f"{where} (built once, kept): {args.segments:,} segments in project Archive + "
          f"{3 * million.SMALL_PROJECT:,} in three others")
    with busy(args.busy):
        time.sleep(30 if args.busy else 0)  # let the load average rise
        print(f"machine: {platform.machine()}, {os.cpu_count()} cores shared with other work, "
              f"{args.busy} busy processes added, load {load()} at the start; "
              f"{args.repeat} timed runs per query; ms\n")
        worst = table(ctx, args.repeat, SegmentListView)
        print(f"\nload at the end: {load()}")
    print(f"worst p95: {worst:.1f} ms (target 50 ms): {'ok' if worst <= 50 else 'MISSED'}")


TABLE = Table([("who", -10, ""), ("query", -29, ""), ("page", 4, ""), ("matched", 10, ""),
               ("med", 8, ".1f"), ("p95", 8, ".1f"), ("CPU", 8, ".1f"), ("SQL", 4, ""),
               ("digest", -8, ""), ("page plan uses", 0, "")])


def table(ctx, repeat, view):
    """Time every query on pages 1 and 100 and print a row each; returns the worst p95."""
    TABLE.print_header()
    worst = 0.0
    for who, title, query in queries(ctx):
        user = ctx["reviewer"] if who == "reviewer" else ctx["annotator"]
        for page in (1, 100):
            q = f"{query}&page={page}" if query else f"page={page}"
            count, times, cpu, n_sql, plan, digest = run_query(user, q, repeat, view)
            worst = max(worst, p95(times)) if times[0] == times[0] else worst
            TABLE.row(who, title, page, count, median(times), p95(times), median(cpu), n_sql,
                      digest, plan)
    return worst
