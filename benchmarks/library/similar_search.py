"""Similar-clip search over a million described segments: the service and the exact
answer, in the same run and under the same load.

Uses the seeded million-segment database of ``million.py`` (built on first use, then
kept). The project "Archive" holds 1,000,000 described segments. The service's index is
built into ``benchmarks/out/`` once (build time printed; later runs bring it in step with
``update``).

For ``--queries`` seeded random segments of the archive, as a reviewer through the view
(``GET /api/segments/{id}/similar/?k=10``, the whole request: the membership lookup, the
index, the database reads, the ranking and the JSON), one path after the other per query:

- ``exact``: the oracle. Profile distances to all 1,000,000 segments in memory (numpy),
  the same exclusions (superseded rows, the query's own overlapping spans, one row per
  span), the 20 nearest re-ranked by DTW exactly as the service does.
- ``service``: the service's similar view with its index.
- ``no index``: the service's fallback (exact scan of the ``SIMILAR_POOL`` most recent
  segments; it never sees the rest, hence its recall), on the first ``--old-queries``.

Then ``--added`` new segments are stored (copies of existing descriptors in a new
capture): searches while they wait for the index, then the service's ``update``, with the
bytes it wrote; then they are deleted, the database vacuumed and the index put back as it
was (its manifest) or, when the update wrote a new generation, brought in step.

The service as an earlier revision shipped it (``45b52fc``: a numpy inverted file, the
candidates' profiles and the shortlist's descriptors read from the database, numpy DTW)
is measured by the same benchmark on that revision's product: ``python -m benchmarks
similar-search --against 45b52fc`` runs it from a worktree of it (on a library of its own,
built by its own migrations on first use), then on this checkout, one after the other.

``--drop-caches`` empties the machine's page cache (as root) just before the queries, as
after a restart or a large read of other files: each service starts from disk, and the
latency of each quarter of the queries shows how soon it recovers.

``--busy N`` adds N processes that spin on a core for the length of the run (stopped at
the end), to measure under load; the load average is printed before and after the
queries. ``--busy-nice K`` runs them at nice ``K``: 0 (the default) is load from
anything else on the machine; 10 is the load of the service's own workers, which ``make
up`` (``scripts/up.py``) runs at nice 10 so that web requests come first. The oracle
answers every query first; then the paths run in turn for each query, with one BLAS
thread. The process is set up as the web server's are (``cutroom/wsgi.py``).
``CPU`` is this process's CPU time per request (the web side; PostgreSQL's share
is not in it): on a shared machine it is the steadier figure.

    python -m benchmarks similar-search [--against REV] [-- --queries 200 --busy 0
        --busy-nice 0 --seed 15]
"""

import argparse
import contextlib
import os
import platform
import statistics
import time
from contextlib import contextmanager
from types import SimpleNamespace
from unittest import mock

import numpy as np

from benchmarks.harness.machine import busy, load, mapped_rss, reclaim
from benchmarks.harness.timing import p95
from benchmarks.library import million


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
    from segmentation.similar import descriptors, search

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


def call_view(user, pk, view=None):
    from rest_framework.test import APIRequestFactory, force_authenticate

    from segmentation.api.similar import SimilarView

    request = APIRequestFactory().get(f"/api/segments/{pk}/similar/?k=10")
    force_authenticate(request, user=user)
    started, cpu = time.perf_counter(), time.process_time()
    response = (view or SimilarView).as_view()(request, pk=pk)
    response.render()
    elapsed = (time.perf_counter() - started) * 1000
    CPU.append((time.process_time() - cpu) * 1000)
    assert response.status_code == 200, response.content[:300]
    return [r["id"] for r in response.data["results"]], elapsed


@contextmanager
def index_dir(path):
    """Point the services at ``path`` for their index files."""
    from django.conf import settings

    previous = settings.SIMILAR_INDEX_DIR
    settings.SIMILAR_INDEX_DIR = path
    try:
        yield
    finally:
        settings.SIMILAR_INDEX_DIR = previous


def vacuum():
    """Leave the database as built: on PostgreSQL, VACUUM skips cleaning the indexes when
    few pages hold deleted rows, and later scans would walk their entries."""
    from django.db import connection

    if connection.vendor == "postgresql":
        with connection.cursor() as cursor:
            cursor.execute("VACUUM (INDEX_CLEANUP ON) segmentation_librarysegment")


def appended_bytes(old, new):
    """Bytes an append wrote, from the states before and after it: each added segment's
    key, vector and descriptor, each removed one's key (the files may hold bytes past
    the old state's counts, which an append overwrites: their sizes do not tell)."""
    added, removed = new["delta"] - old["delta"], new["removed"] - old["removed"]
    return added * (8 + 4 * new["ndim"] + 4 * new["payload"]) + removed * 8


def ensure(module, project, folder):
    """Build (or bring in step) ``module``'s index of ``project`` in ``folder``; returns
    (manifest, seconds, what was done)."""
    with index_dir(folder):
        started = time.perf_counter()
        fresh = not module.manifest_path(project).exists()
        manifest = module.build(project) if fresh else module.update(project)
        return manifest, time.perf_counter() - started, "built" if fresh else "brought in step"


def similar_steps():
    """(steps, scheduler, opener): the similar index's steps under one name, the module
    whose ``schedule_update`` the service calls and the one whose ``open_index`` it calls — one module in revisions before
    ``segmentation/similar/``, the package's modules since."""
    try:
        from segmentation.similar import files, index, updates
    except ImportError:  # an older revision (--against)
        from segmentation import similar_index
        return similar_index, similar_index, similar_index
    from motionlib import vector_index
    steps = SimpleNamespace(
        build=updates.build, update=updates.update, manifest_path=files.manifest_path,
        read_manifest=files.read_manifest, forget=index.forget, vector_index=vector_index)
    return steps, updates, index


def index_kind(similar_index, manifest):
    """The service's index as the run's header describes it: faiss (with its probe count)
    or, in revisions before it, the numpy inverted file (with its probe share)."""
    if hasattr(similar_index, "PROBE_SHARE"):
        return (f"numpy IVF, {manifest['lists']:,} lists, float16, scans "
                f">= {similar_index.PROBE_SHARE:.1%}")
    return (f"faiss IVF, {manifest['lists']:,} lists, nprobe "
            f"{similar_index.vector_index.NPROBE}, float32, descriptors beside it; "
            f"{manifest['count']:,} vectors")


def table(rows, recall, cpu):
    header = (f"{'path':<30} {'queries':>7} {'median ms':>10} {'p95 ms':>8} {'CPU med ms':>11} "
              f"{'recall@10':>10}")
    print(header)
    print("-" * len(header))
    for title, times in rows.items():
        r, c = recall.get(title), cpu.get(title)
        print(f"{title:<30} {len(times):>7} {statistics.median(times):>10.1f} {p95(times):>8.1f} "
              f"{statistics.median(c) if c else float('nan'):>11.1f} "
              f"{np.mean(r) if r else 1.0:>10.3f}")


def main():
    # One BLAS thread: the oracle's large products would otherwise leave OpenBLAS threads
    # spinning on both cores while the next request is timed (a web process makes no such
    # products).
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        run()


def run():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--segments", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=15)
    parser.add_argument("--queries", type=int, default=200)
    parser.add_argument("--old-queries", type=int, default=10)
    parser.add_argument("--added", type=int, default=5000)
    parser.add_argument("--busy", type=int, default=0)
    parser.add_argument("--busy-nice", type=int, default=0,
                        help="nice value of the busy processes (10: as the service's workers)")
    parser.add_argument("--nprobe", type=int, help="lists a search scans (default: the service's)")
    parser.add_argument("--drop-caches", action="store_true",
                        help="empty the page cache before the queries (root): every file on disk")
    parser.add_argument("--admin-url", default=million.default_admin_url())
    args = parser.parse_args()
    name, out = million.connect(args.admin_url, args.segments, args.seed)
    # Set up as a web server process is (cutroom/wsgi.py: the URLconf loaded, then
    # gc.freeze()), so no full collection rescans the start-up objects inside a request.
    import cutroom.wsgi  # noqa: F401
    from segmentation.models import Capture, LibrarySegment

    similar_index, scheduler, opener = similar_steps()

    if args.nprobe:
        similar_index.vector_index.NPROBE = args.nprobe
    ctx = million.personas()
    project = ctx["project"].pk
    folder = out / "similar-now"
    manifest, built, how = ensure(similar_index, project, folder)
    ids, profiles, spans = oracle_arrays(out)
    rng = np.random.default_rng(args.seed)
    picks = [int(i) for i in rng.choice(ids[spans[:, 4] == 0], size=args.queries, replace=False)]
    segments = LibrarySegment.objects.in_bulk(picks)
    print(f"database {name}: {len(ids):,} described segments in project Archive "
          f"(descriptor 35 x 35 float32, profile 105 numbers)")
    print(f"service: {index_kind(similar_index, manifest)}; {manifest['bytes'] / 1e6:,.0f} MB "
          f"of files; {how} in {built:.1f} s")
    spinning = contextlib.ExitStack()
    spinning.enter_context(busy(args.busy, args.busy_nice))
    try:
        time.sleep(30 if args.busy else 0)  # let the load average rise
        print(f"machine: {platform.machine()}, {os.cpu_count()} cores shared with other work, "
              f"{args.busy} busy processes added (nice {args.busy_nice}); load {load()} before the queries; "
              f"{args.queries} queries (no-index path: first {args.old_queries}), k=10, "
              f"reviewer, through SimilarView; {reclaim()}\n", flush=True)
        if args.drop_caches:
            os.sync()
            try:
                with open("/proc/sys/vm/drop_caches", "w") as f:
                    f.write("3\n")
            except OSError as exc:
                raise SystemExit(f"--drop-caches: cannot empty the page cache ({exc})") from exc
            print("page cache emptied before the queries (--drop-caches): the index files, "
                  "PostgreSQL's files and the oracle's arrays start on disk\n", flush=True)
        if hasattr(similar_index, "forget"):
            similar_index.forget()
        user = ctx["reviewer"]
        paths = {"service": None}
        folders = {"service": folder}
        rows = {"exact (oracle, numpy)": [], **{p: [] for p in paths}, "no index (20,000 recent)": []}
        recall = {p: [] for p in rows if p != "exact (oracle, numpy)"}
        cpu = {p: [] for p in recall}
        # The oracle's answers first: its sweep over 420 MB of profiles between two
        # requests would leave every request to start with cold caches, which a web
        # server answering searches one after another does not.
        truths = {}
        for pk in picks:
            started = time.perf_counter()
            truths[pk] = exact_top(segments[pk], ids, profiles, spans)
            rows["exact (oracle, numpy)"].append((time.perf_counter() - started) * 1000)
        for n, pk in enumerate(picks):
            truth = truths[pk]
            for title, view in paths.items():
                with index_dir(folders[title]):
                    found, ms = call_view(user, pk, view)
                rows[title].append(ms)
                cpu[title].append(CPU[-1])
                recall[title].append(len(set(found) & set(truth)) / len(truth))
            if n < args.old_queries:
                with index_dir(out / "none"), mock.patch.object(opener, "open_index",
                                                               lambda project_id: None):
                    found, ms = call_view(user, pk)
                rows["no index (20,000 recent)"].append(ms)
                cpu["no index (20,000 recent)"].append(CPU[-1])
                recall["no index (20,000 recent)"].append(len(set(found) & set(truth)) / len(truth))
            if n % 50 == 49:
                print(f"  {n + 1} queries done (load {load()})", flush=True)
        print(f"load {load()} after the queries\n")
        table(rows, recall, cpu)
        if args.drop_caches:
            print("\nfrom disk, by quarter of the queries (median / p95 ms):")
            quarter = max(1, len(picks) // 4)
            for title in paths:
                spans = [rows[title][i:i + quarter] for i in range(0, len(picks), quarter)]
                print(f"  {title:<28} " + "   ".join(
                    f"{statistics.median(t):5.1f} / {p95(t):6.1f}" for t in spans if t))
        from django.conf import settings

        if getattr(settings, "SIMILAR_INDEX_IN_MEMORY", False):
            base = (folder / manifest["file"] / similar_index.vector_index.BASE).stat().st_size
            print(f"\nservice: the faiss base in this process's own memory "
                  f"(SIMILAR_INDEX_IN_MEMORY), {base / 1e6:.0f} MB")
        elif hasattr(similar_index, "vector_index"):
            rss, pss = mapped_rss(".faiss")
            print(f"\nservice: the faiss base mapped, resident in this process {rss / 1e3:.0f} "
                  f"MB (Pss {pss / 1e3:.0f} MB)")

        # Segments waiting for the index, then each service's update. The index as it is
        # now is put back afterwards (its manifest: a reader sees the records it counts),
        # so that runs do not pile up added-then-removed records in it.
        kept = similar_index.manifest_path(project).name
        kept = (folder / kept).read_bytes()
        capture = Capture.objects.create(project_id=project, name="bench_added.bvh",
                                         checksum="bench_added", format="bvh", status="ready",
                                         fps=120.0, n_frames=200_000, original="captures/added.bvh")
        source = LibrarySegment.objects.filter(
            pk__in=[int(i) for i in rng.choice(ids, args.added, replace=False)])
        added = LibrarySegment.objects.bulk_create(
            LibrarySegment(project_id=project, capture=capture, annotator_id=s.annotator_id,
                           label_id=s.label_id, start=i, stop=i + 100, duration=100 / 120,
                           descriptor=s.descriptor, descriptor_shape=s.descriptor_shape,
                           profile=s.profile) for i, s in enumerate(source))
        try:
            waiting = {p: [] for p in paths}
            with mock.patch.object(scheduler, "schedule_update", lambda project_id: None):
                for pk in picks[:40]:
                    for title, view in paths.items():
                        with index_dir(folders[title]):
                            waiting[title].append(call_view(user, pk, view)[1])
            print(f"\n{len(added):,} new segments waiting for the index, load {load()}:")
            for title, times in waiting.items():
                print(f"  {title:<28} median {statistics.median(times):6.1f} ms, p95 {p95(times):6.1f} ms")
            print("updates that take them in:")
            for title, module in (("service", similar_index),):
                with index_dir(folders[title]):
                    first = module.read_manifest(project)
                    started = time.perf_counter()
                    after = module.update(project)
                    took = time.perf_counter() - started
                appended = after["file"] == first["file"]
                written = appended_bytes(first["state"], after["state"]) if appended else after["bytes"]
                print(f"  {title:<28} {took:6.1f} s, wrote {written / 1e6:8.1f} MB "
                      f"({'appended' if appended else 'a new generation of the whole index'})")
        finally:
            LibrarySegment.objects.filter(pk__in=[s.pk for s in added]).delete()
            capture.delete()
            vacuum()
            with index_dir(folder):
                if similar_index.read_manifest(project)["file"] == manifest["file"]:
                    similar_index.manifest_path(project).write_bytes(kept)
                else:  # compacted: a new generation
                    similar_index.update(project)
    finally:
        spinning.close()
    print(f"\nworst: service p95 {p95(rows['service']):.1f} ms (target 10 on a quiet machine, "
          f"20 at load 4), recall@10 {np.mean(recall['service']):.3f} (target 0.99), min per "
          f"query {min(recall['service']):.1f}")

