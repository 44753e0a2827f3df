"""Vector index libraries on the million-segment library's profiles: build, search, recall.

Reads the 105-number profiles that ``million.py`` caches (``benchmarks/out/million_*/
profiles.npy``) and, for each library that imports here, builds an index of all of them
on this machine and searches it with ``--queries`` of the stored profiles (seeded): the
10 nearest, one query at a time, as a web request asks. Recall@10 is against the exact
answer (numpy, float64 over all vectors).

- ``numpy IVF``: ``motionlib.vector_index.IvfIndex``, the service's index before faiss
  (float16 lists, scans 0.5 % of the vectors, at least 8 lists), in the revisions that
  have it: ``python -m benchmarks index-libraries --against 45b52fc`` prints its row
  (from a worktree of that revision) beside this checkout's table.
- ``faiss IVF``: ``IndexIVFFlat`` (float32 lists) as ``motionlib.vector_index`` builds it,
  at its ``nprobe``; also written, then read back memory-mapped (``IO_FLAG_MMAP |
  IO_FLAG_READ_ONLY``) in two processes, whose resident and proportional (``Pss``)
  sizes of the mapping show whether they share one copy in the page cache.
- ``usearch HNSW`` and ``hnswlib HNSW``: graph indexes (M 16, ef_construction 128,
  ef 64), built with every core; usearch's file is also viewed memory-mapped.

    python -m benchmarks index-libraries [-- --profiles PATH --queries 500]
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.harness import OUT
from motionlib import vector_index


def exact(x, queries, k):
    out = []
    norms = np.einsum("ij,ij->i", x, x)
    for q in queries:
        d = norms - 2.0 * (x @ q)
        near = np.argpartition(d, 200)[:200]
        diff = x[near].astype(np.float64) - q.astype(np.float64)
        out.append(near[np.argsort(np.einsum("ij,ij->i", diff, diff), kind="stable")[:k]])
    return out


def timed_search(search, queries, truth, k):
    times, recall = [], []
    for q, t in zip(queries, truth, strict=True):
        started = time.perf_counter()
        found = search(q)
        times.append((time.perf_counter() - started) * 1000)
        recall.append(len(set(map(int, found[:k])) & set(map(int, t))) / k)
    return statistics.median(times), statistics.quantiles(times, n=20)[-1], float(np.mean(recall))


MAPPED = """
import faiss, json, sys, time, numpy as np
path, out = sys.argv[1], sys.argv[2]
from benchmarks.harness.machine import mapped_rss
index = faiss.read_index(path, faiss.IO_FLAG_MMAP | faiss.IO_FLAG_READ_ONLY)
index.nprobe = int(sys.argv[3])
q = np.load(sys.argv[4])
for row in q:
    index.search(row[None, :], 10)
open(out, "w").write(json.dumps(mapped_rss(path)))
time.sleep(float(sys.argv[5]))
"""


def faiss_sharing(path, nprobe, queries_path):
    """Two processes map the file and search; returns [[rss kB, pss kB]] of each."""
    outs = [tempfile.mktemp(suffix=".json") for _ in range(2)]
    procs = [subprocess.Popen([sys.executable, "-c", MAPPED, str(path), o, str(nprobe),
                               str(queries_path), "6"]) for o in outs]
    time.sleep(0.5)
    for p in procs:
        p.wait(120)
    return [json.loads(Path(o).read_text()) for o in outs]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--profiles", type=Path,
                        default=OUT / "million_1000000_s35" / "profiles.npy")
    parser.add_argument("--queries", type=int, default=500)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--skip-hnsw", action="store_true",
                        help="leave the graph indexes out (their builds take minutes)")
    args = parser.parse_args()
    x = np.ascontiguousarray(np.load(args.profiles), dtype=np.float32)
    n, d = x.shape
    rng = np.random.default_rng(args.seed)
    queries = x[rng.choice(n, size=args.queries, replace=False)]
    k = 10
    truth = exact(x, queries, k)
    ids = np.arange(n, dtype=np.int64)
    print(f"{n:,} profiles of {d} numbers ({args.profiles.parent.name}); {args.queries} queries, "
          f"k={k}, one query at a time; {os.cpu_count()} cores shared with other work, load "
          f"{', '.join(f'{v:.1f}' for v in os.getloadavg())} at the start\n")
    header = (f"{'library':<26} {'build s':>8} {'added/s':>9} {'p50 ms':>7} {'p95 ms':>7} "
              f"{'recall@10':>10} {'file MB':>8}  shared mapping")
    print(header)
    print("-" * len(header))
    tmp = Path(tempfile.mkdtemp())

    def row(name, build_s, p50, p95, recall, mb, shared):
        print(f"{name:<26} {build_s:>8.1f} {n / build_s:>9,.0f} {p50:>7.2f} {p95:>7.2f} "
              f"{recall:>10.3f} {mb:>8.0f}  {shared}", flush=True)

    if hasattr(vector_index, "IvfIndex"):  # the product's own index before faiss
        started = time.perf_counter()
        ivf = vector_index.IvfIndex.build(ids, x)
        built = time.perf_counter() - started
        r = timed_search(lambda q: ivf.search(q, k, probe_share=0.005)[0], queries, truth, k)
        mb = sum(ivf.save(tmp / "numpy").values()) / 1e6
        row("numpy IVF", built, *r, mb, "yes (np.load mmap_mode='r')")
        ivf = None  # free its memory before the next library

    try:
        import faiss
    except ImportError:
        faiss = None
        print("faiss: not installed")
    if faiss is not None and hasattr(vector_index, "build"):  # the product's faiss index
        faiss.omp_set_num_threads(os.cpu_count())
        started = time.perf_counter()
        vector_index.build(tmp / "faiss", ids, x)
        built = time.perf_counter() - started
        path = tmp / "faiss" / vector_index.BASE
        index = faiss.read_index(str(path))
        index.nprobe = vector_index.NPROBE
        faiss.omp_set_num_threads(1)
        r = timed_search(lambda q: index.search(q[None, :], k)[1][0], queries, truth, k)
        np.save(tmp / "queries.npy", queries[:200])
        mapped = faiss.read_index(str(path), faiss.IO_FLAG_MMAP | faiss.IO_FLAG_READ_ONLY)
        mapped.nprobe = vector_index.NPROBE
        rm = timed_search(lambda q: mapped.search(q[None, :], k)[1][0], queries, truth, k)
        both = faiss_sharing(path, vector_index.NPROBE, tmp / "queries.npy")
        shared = ("; ".join(f"process {i + 1}: Rss {a / 1e3:.0f} MB, Pss {b / 1e3:.0f} MB"
                            for i, (a, b) in enumerate(both)))
        row(f"faiss IVF, nprobe {vector_index.NPROBE}", built, *r, path.stat().st_size / 1e6,
            "in memory")
        row("  same, read mmap", built, *rm, path.stat().st_size / 1e6,
            f"yes: {shared}")
        del index, mapped

    if args.skip_hnsw:
        return
    try:
        from usearch.index import Index
    except ImportError:
        print("usearch: not installed")
    else:
        index = Index(ndim=d, metric="l2sq", dtype="f32", connectivity=16, expansion_add=128,
                      expansion_search=64)
        started = time.perf_counter()
        index.add(ids, x, threads=os.cpu_count())
        built = time.perf_counter() - started
        r = timed_search(lambda q: index.search(q, k).keys, queries, truth, k)
        path = tmp / "usearch.index"
        index.save(str(path))
        view = Index.restore(str(path), view=True)
        rv = timed_search(lambda q: view.search(q, k).keys, queries, truth, k)
        row("usearch HNSW f32", built, *r, path.stat().st_size / 1e6, "in memory")
        row("  same, viewed mmap", built, *rv, path.stat().st_size / 1e6, "yes (view=True)")
        del index, view

    try:
        import hnswlib
    except ImportError:
        print("hnswlib: not installed")
    else:
        index = hnswlib.Index(space="l2", dim=d)
        index.init_index(max_elements=n, M=16, ef_construction=128)
        index.set_num_threads(os.cpu_count())
        started = time.perf_counter()
        index.add_items(x, ids)
        built = time.perf_counter() - started
        index.set_ef(64)
        index.set_num_threads(1)
        r = timed_search(lambda q: index.knn_query(q, k)[0][0], queries, truth, k)
        path = tmp / "hnswlib.index"
        index.save_index(str(path))
        row("hnswlib HNSW f32", built, *r, path.stat().st_size / 1e6,
            "no (load_index reads it into each process)")

