"""Library list benchmark on PostgreSQL: a million segments, first and 100th page.

Uses the seeded million-segment database of ``million.py`` (built on first use, about
ten minutes, then kept; see there for what it holds) and times ``GET /api/segments/``
(the real view: role filter, query-string filters, one page with its count) for typical
filters, each on page 1 and page 100, twice: with the page-number pagination that counts
every match (``old``: Django REST framework's ``PageNumberPagination``, what the list
used before) and with the current one (``new``: exact count up to 10,000 matches,
capped beyond). One row per query and page: rows matched (``10,000+`` = capped), median
and 95th-percentile milliseconds of each, SQL queries per request of the new one, and
the indexes PostgreSQL's plan uses for its page query.

    DATABASE_ADMIN_URL=postgres://postgres@127.0.0.1:5432/postgres \\
        .venv/bin/python benchmarks/library_query.py [--segments 1000000] [--repeat 20]
"""

import argparse
import os
import platform
import re
import statistics
import time

import million


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


PLAN_INDEX = re.compile(r"(?:Index(?: Only)? Scan(?: Backward)? using|Bitmap Index Scan on) (\w+)")


def plan_of(sql):
    from django.db import connection

    with connection.cursor() as cursor:
        cursor.execute("EXPLAIN " + sql)
        text = "\n".join(row[0] for row in cursor.fetchall())
    used = sorted(set(PLAN_INDEX.findall(text)))
    return ", ".join(used) + (" + seq scan" if "Seq Scan" in text else "") or "seq scan"


def old_pagination():
    """The list as it paged before: DRF page numbers with an exact count of all matches."""
    from rest_framework.pagination import PageNumberPagination

    class Paginator(PageNumberPagination):
        page_size = 50
        page_size_query_param = "page_size"
        max_page_size = 500

    return Paginator


def run_query(user, query, repeat, pagination=None):
    from django.db import connection
    from django.test.utils import CaptureQueriesContext
    from rest_framework.test import APIRequestFactory, force_authenticate

    from segmentation.api.segments import SegmentListView

    view = SegmentListView.as_view(**({"pagination_class": pagination} if pagination else {}))
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
        if response.status_code == 404:
            return "no page", [float("nan")], 0, "(fewer than 100 pages)"
        if response.status_code != 200:
            raise SystemExit(f"{query}: HTTP {response.status_code} {response.content[:200]!r}")
        if i:  # the first run warms caches
            times.append(elapsed * 1000)
    page_sql = next(q["sql"] for q in captured if "LIMIT" in q["sql"] and "COUNT" not in q["sql"])
    count = f"{response.data['count']:,}" + ("+" if response.data.get("count_capped") else "")
    return count, times, len(captured), plan_of(page_sql)


def p95(times):
    return statistics.quantiles(times, n=20)[-1] if len(times) > 1 else times[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--repeat", type=int, default=20)
    parser.add_argument("--no-old", action="store_true", help="time the new pagination only")
    parser.add_argument("--admin-url", default=million.default_admin_url())
    args = parser.parse_args()
    name, _ = million.connect(args.admin_url, args.segments, args.seed)
    ctx = million.personas()
    from segmentation.models import LibrarySegment

    ctx["capture"] = (LibrarySegment.objects.filter(project=ctx["project"]).order_by("id")
                      .values_list("capture_id", flat=True).first())
    print(f"database {name}: {args.segments:,} segments in project Archive + "
          f"{3 * million.SMALL_PROJECT:,} in three others (PostgreSQL, cached)")
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores shared with other work, load "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}; {args.repeat} timed runs each, "
          "old then new per query\n")
    header = (f"{'who':<10} {'query':<29} {'page':>4} {'matched':>10} {'old med':>8} {'old p95':>8} "
              f"{'new med':>8} {'new p95':>8} {'SQL':>4}  page plan uses")
    print(header)
    print("-" * len(header))
    worst = 0.0
    for who, title, query in queries(ctx):
        user = ctx["reviewer"] if who == "reviewer" else ctx["annotator"]
        for page in (1, 100):
            q = f"{query}&page={page}" if query else f"page={page}"
            old = [float("nan")] if args.no_old else run_query(user, q, args.repeat, old_pagination())[1]
            count, times, n_sql, plan = run_query(user, q, args.repeat)
            worst = max(worst, p95(times)) if times[0] == times[0] else worst
            print(f"{who:<10} {title:<29} {page:>4} {count:>10} {statistics.median(old):>8.1f} "
                  f"{p95(old):>8.1f} {statistics.median(times):>8.1f} {p95(times):>8.1f} "
                  f"{n_sql:>4}  {plan}", flush=True)
    print(f"\nworst new p95: {worst:.1f} ms (target 100 ms)")


if __name__ == "__main__":
    main()
