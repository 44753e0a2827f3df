"""Similar-clip search over a million described segments: the vector index beside the
exact scan.

Uses the seeded million-segment database of ``million.py`` (built on first use, then
kept). The project "Archive" holds 1,000,000 described segments. Its similar-clip index
(``segmentation.similar_index``) is built into ``benchmarks/out/`` once (the build time is
printed; later runs bring the cached file in step with ``update``).

For ``--queries`` seeded random segments of the archive, as a reviewer through the real
view (``GET /api/segments/{id}/similar/?k=10``):

- ``exact``: the oracle. Profile distances to all 1,000,000 segments in memory (numpy),
  the same exclusions (superseded rows, the query's own overlapping spans, one row per
  span), the 20 nearest re-ranked by DTW exactly as the service does.
- ``index``: the service with its index (what a studio gets).
- ``old``: the service without an index (its scan of the ``SIMILAR_POOL`` = 20,000 most
  recent segments, what it did before; it never sees the other 980,000, hence its
  recall). Timed on the first ``--old-queries`` queries only.

Prints latency (median, p95), recall@10 against ``exact``, and the index's memory: file
size (the most the page cache ever holds for all web processes together, since they map
the same file read-only) and what this process has resident of the mapping after the
queries (``/proc/self/smaps``). ``CPU`` is this process's CPU time per request (the web
side; PostgreSQL's share is not in it): on a shared machine it is the steadier figure.

    .venv/bin/python benchmarks/similar_search.py [--queries 200] [--old-queries 20]
"""

import argparse
import os
import platform
import statistics
import time
from unittest import mock

import million
import numpy as np


def oracle_arrays(out):
    """ids, profiles, capture, start, stop, superseded of the archive (cached as .npy)."""
    path = out / "spans.npy"
    if not path.exists():
        from segmentation.models import LibrarySegment

        project = million.personas()["project"]
        rows = np.array(list(LibrarySegment.objects.filter(project=project).order_by("id")
                             .values_list("id", "capture_id", "start", "stop", "superseded")
                             .iterator(chunk_size=50_000)), dtype=np.int64)
        np.save(path, rows)
    spans = np.load(path)
    ids = np.load(out / "ids.npy")
    assert np.array_equal(ids, spans[:, 0]), "cached arrays disagree with the database"
    return ids, Profiles(np.load(out / "profiles.npy")), spans


def exact_top(segment, ids, profiles, spans, k=10):
    """The oracle's ``k`` ids for ``segment`` (a LibrarySegment).

    ``profiles`` (n, 105) float32 in memory. Squared distances to all of them in float32
    (as |x|^2 - 2 x.q + |q|^2) pick the 2,000 nearest; those are measured again exactly as
    the service measures (float64 differences), far more than the 20 the ranking needs."""
    from motionlib import similarity
    from segmentation import descriptors, search

    query = segment.descriptor_array()
    q = query[:similarity.PROFILE_ROWS].ravel()
    d = profiles.norms - 2.0 * (profiles.x @ q)
    keep = (spans[:, 4] == 0) & ~((spans[:, 1] == segment.capture_id) & (spans[:, 2] < segment.stop)
                                  & (spans[:, 3] > segment.start))
    d[~keep] = np.inf
    near = np.argpartition(d, 2000)[:2000]
    diff = profiles.x[near].astype(np.float64) - q.astype(np.float64)
    exact = np.einsum("ij,ij->i", diff, diff)
    exact[~keep[near]] = np.inf
    # Ties (one span twice) resolve to the newest row, as in the service.
    order = near[np.lexsort((-ids[near], exact))]
    short, seen = [], set()
    for i in order:
        span = (spans[i, 1], spans[i, 2], spans[i, 3])
        if span not in seen:
            seen.add(span)
            short.append(int(ids[i]))
        if len(short) == max(search.SHORTLIST, k):
            break
    found, _ = similarity.rank_similar(query, descriptors.load_descriptors(short), k=k,
                                       shortlist=len(short))
    return [short[i] for i in found]


class Profiles:
    """The archive's profiles in memory with their squared norms."""

    def __init__(self, x):
        self.x = np.ascontiguousarray(x, dtype=np.float32)
        self.norms = np.einsum("ij,ij->i", self.x, self.x)


CPU = []


def call_view(user, pk):
    from rest_framework.test import APIRequestFactory, force_authenticate

    from segmentation.api.similar import SimilarView

    request = APIRequestFactory().get(f"/api/segments/{pk}/similar/?k=10")
    force_authenticate(request, user=user)
    started, cpu = time.perf_counter(), time.process_time()
    response = SimilarView.as_view()(request, pk=pk)
    response.render()
    elapsed = (time.perf_counter() - started) * 1000
    CPU.append((time.process_time() - cpu) * 1000)
    assert response.status_code == 200, response.content[:300]
    return [r["id"] for r in response.data["results"]], elapsed


def mapped_rss(name):
    """kB of ``name``'s memory map resident in this process (Rss, Pss)."""
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


def p95(times):
    return statistics.quantiles(times, n=20)[-1] if len(times) > 1 else times[0]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--queries", type=int, default=200)
    parser.add_argument("--old-queries", type=int, default=20)
    parser.add_argument("--admin-url", default=million.default_admin_url())
    args = parser.parse_args()
    name, out = million.connect(args.admin_url, args.segments, args.seed)
    from django.conf import settings

    from segmentation import similar_index
    from segmentation.models import LibrarySegment

    settings.SIMILAR_INDEX_DIR = out / "similar"
    ctx = million.personas()
    project = ctx["project"].pk
    started = time.perf_counter()
    fresh = not similar_index.manifest_path(project).exists()
    manifest = similar_index.build(project) if fresh else similar_index.update(project)
    built = time.perf_counter() - started
    ids, profiles, spans = oracle_arrays(out)
    rng = np.random.default_rng(args.seed)
    picks = [int(i) for i in rng.choice(ids[spans[:, 4] == 0], size=args.queries, replace=False)]
    segments = LibrarySegment.objects.in_bulk(picks)
    print(f"database {name}: {len(ids):,} described segments in project Archive "
          f"(descriptor 35 x 35 float32, profile 105 numbers)")
    print(f"index: inverted file (motionlib.vector_index), {manifest['lists']:,} k-means lists, "
          f"float16, scans >= {similar_index.PROBE_SHARE:.1%} per search; "
          f"{manifest['count']:,} vectors, {manifest['bytes'] / 1e6:.0f} MB of files; "
          f"{'built' if fresh else 'brought in step (cached)'} in {built:.1f} s")
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores shared with other work, load "
          f"{', '.join(f'{x:.1f}' for x in os.getloadavg())}; {args.queries} queries "
          f"(old path: first {args.old_queries}), k=10, reviewer, through SimilarView\n")
    similar_index.forget()
    rss_before = mapped_rss("vectors.npy")
    rows = {"exact (oracle, numpy in memory)": [], "index": [], "old (20,000 recent)": []}
    recall = {"index": [], "old (20,000 recent)": []}
    cpu = {"index": [], "old (20,000 recent)": []}
    user = ctx["reviewer"]
    for n, pk in enumerate(picks):
        started = time.perf_counter()
        truth = exact_top(segments[pk], ids, profiles, spans)
        rows["exact (oracle, numpy in memory)"].append((time.perf_counter() - started) * 1000)
        found, ms = call_view(user, pk)
        rows["index"].append(ms)
        cpu["index"].append(CPU[-1])
        recall["index"].append(len(set(found) & set(truth)) / len(truth))
        if n % 20 == 19:
            print(f"  {n + 1} queries done", flush=True)
        if n < args.old_queries:
            with mock.patch.object(similar_index, "open_index", lambda project_id: None):
                found, ms = call_view(user, pk)
            rows["old (20,000 recent)"].append(ms)
            cpu["old (20,000 recent)"].append(CPU[-1])
            recall["old (20,000 recent)"].append(len(set(found) & set(truth)) / len(truth))
    rss, pss = mapped_rss("vectors.npy")
    header = (f"{'path':<34} {'queries':>7} {'median ms':>10} {'p95 ms':>8} {'CPU med ms':>11} "
              f"{'recall@10':>10}")
    print(header)
    print("-" * len(header))
    for title, times in rows.items():
        r, c = recall.get(title), cpu.get(title)
        print(f"{title:<34} {len(times):>7} {statistics.median(times):>10.1f} {p95(times):>8.1f} "
              f"{statistics.median(c) if c else float('nan'):>11.1f} {np.mean(r) if r else 1.0:>10.3f}")
    print(f"\nindex memory: files {manifest['bytes'] / 1e6:.0f} MB (ids + vectors mapped read-only, "
          f"shared by every process); vectors.npy "
          f"resident in this process before the queries {rss_before[0] / 1e3:.0f} MB, after "
          f"{rss / 1e3:.0f} MB (Pss {pss / 1e3:.0f} MB)")
    print(f"worst: index p95 {p95(rows['index']):.1f} ms (target 50), recall@10 "
          f"{np.mean(recall['index']):.3f} (target 0.95), min per query {min(recall['index']):.1f}")


if __name__ == "__main__":
    main()
