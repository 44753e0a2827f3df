"""Library list filtered by a segment attribute (``attribute=name:value``) on SQLite.

Builds the seeded library of ``million_sqlite`` at ``--segments`` rows (built once, kept,
under ``benchmarks/out/``), gives the Archive project two attributes and its segments
values at three frequencies (``quality`` good on ~60 %, unusable on ~1 %; ``needs
cleanup`` true on ~0.1 %), then times ``GET /api/segments/`` (the real view, page 1, page
size 50) for the list without an attribute filter and with each, alone and with a label.
Columns as ``library-list``: rows matched, median and p95 ms, median CPU ms, SQL queries,
the indexes the page query's plan uses.

*Old* is the filter as first written, an ``EXISTS`` on the value table's ``(attribute,
value, segment)`` index probed for each segment the list walks newest first: a rare value
costs a probe per segment walked before 50 match, and the capped count walks them all.
*New* (``queries.library.attribute_q``) walks so only for a value carried by at least
``COMMON_VALUE_ROWS`` rows, counted first from the value index; a rarer value is sought in
that index (``id IN``) and its few rows sorted. Both run in the same process, one after
the other, on the same file.

    python -m benchmarks library-attribute-filter [-- --segments 200000 --repeat 10]
"""

import argparse
import os
import platform

import numpy as np

from benchmarks.harness.machine import load
from benchmarks.harness.timing import Table, median, p95
from benchmarks.library import million, million_sqlite
from benchmarks.library.listing import run_query

TABLE = Table([("query", -34, ""), ("matched", 10, ""), ("old med", 8, ".1f"), ("old p95", 8, ".1f"),
               ("new med", 8, ".1f"), ("new p95", 8, ".1f"), ("new CPU", 8, ".1f"), ("SQL", 4, ""),
               ("new page plan uses", 0, "")])


def give_values(project, seed):
    """The project's attributes and its segments' values (once: kept with the file)."""
    from segmentation.models import LibraryAttributeValue, LibrarySegment, SegmentAttribute

    if SegmentAttribute.objects.filter(project=project).exists():
        return
    quality = SegmentAttribute.objects.create(project=project, name="quality", kind="choice",
                                              options=["good", "usable", "unusable"])
    cleanup = SegmentAttribute.objects.create(project=project, name="needs cleanup", kind="boolean")
    ids = np.array(LibrarySegment.objects.filter(project=project).values_list("id", flat=True))
    rng = np.random.default_rng(seed)
    draw = rng.random(len(ids))
    rows = [LibraryAttributeValue(segment_id=int(pk), attribute=quality,
                                  value="good" if x < 0.6 else "usable" if x < 0.99 else "unusable")
            for pk, x in zip(ids, draw, strict=True)]
    rows += [LibraryAttributeValue(segment_id=int(pk), attribute=cleanup, value="true")
             for pk in ids[rng.random(len(ids)) < 0.001]]
    LibraryAttributeValue.objects.bulk_create(rows, batch_size=5000)
    print(f"[attributes] {len(rows):,} values on {len(ids):,} segments")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=200_000)
    parser.add_argument("--seed", type=int, default=49)
    parser.add_argument("--repeat", type=int, default=10)
    args = parser.parse_args()
    path = million_sqlite.connect(args.segments, args.seed)
    ctx = million.personas()
    give_values(ctx["project"], args.seed)
    import cutroom.wsgi  # noqa: F401  (the process set up as a web server's)
    from segmentation.api.segments import SegmentListView

    p = ctx["project"].pk
    print(f"SQLite file {path.name}: {args.segments:,} segments in project Archive; "
          f"machine {platform.machine()}, {os.cpu_count()} cores shared with other work, load "
          f"{load()} at the start; {args.repeat} timed runs per query, reviewer, page 1; ms\n")
    TABLE.print_header()
    from segmentation.queries import library

    for title, query in (("project, no attribute filter", f"project={p}"),
                         ("quality:good (~60 %)", f"project={p}&attribute=quality:good"),
                         ("quality:unusable (~1 %)", f"project={p}&attribute=quality:unusable"),
                         ("needs cleanup:true (~0.1 %)", f"project={p}&attribute=needs cleanup:true"),
                         ("label walk, no attribute filter", f"project={p}&label=walk"),
                         ("label walk + quality:unusable", f"project={p}&label=walk&attribute=quality:unusable"),
                         ("all projects + quality:unusable", "attribute=quality:unusable")):
        threshold, library.COMMON_VALUE_ROWS = library.COMMON_VALUE_ROWS, 0  # always walk
        try:
            _, old, _, _, _, old_page = run_query(ctx["reviewer"], query, args.repeat, SegmentListView)
        finally:
            library.COMMON_VALUE_ROWS = threshold
        count, times, cpu, n_sql, plan, page = run_query(ctx["reviewer"], query, args.repeat, SegmentListView)
        assert page == old_page, f"{title}: the old and new pages differ"
        TABLE.row(title, count, median(old), p95(old), median(times), p95(times), median(cpu), n_sql, plan)
    print(f"\nload at the end: {load()}; old and new pages hold the same segments: yes, every query")


if __name__ == "__main__":
    main()
