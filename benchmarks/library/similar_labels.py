"""Similar-clip search on the labelled CMU takes: does the nearest clip show the same action?

The mocap6 takes 13_29 and 13_30 (same actor, human labels) are cut into consecutive clips
inside each labelled action (half a second trimmed at each end, since the labels mark
10 fps blocks). Two settings, one row per action and setting:

- ``13_29 leave-one-out``: each 13_29 clip searched among the other 13_29 clips;
- ``13_30 -> 13_29``: each 13_30 clip searched in the 13_29 library (13_30's Jog has no
  counterpart in 13_29 and is left out).

Each setting runs three times: the exact ranking (``rank_similar`` over the whole
library), through the service's vector index at its own parameters (``[index]``), and
through an index of 4 clips per list scanning as few lists as it can, so that it probes (``[index N lists]``).

Columns: clips, share whose nearest clip is the same action (top-1), mean share of the
same action among the 5 nearest (precision@5; capped when an action has fewer than five
other clips, e.g. 13_29's JumpJack has one), and search time per query.

    .venv/bin/python -m benchmarks similar-labels -- [--clip-seconds 1.0]
"""

import argparse
import shutil
import tempfile
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

import motionlib
from benchmarks.harness import data_dir
from motionlib.similarity import (
    PROFILE_ROWS,
    body_scale,
    rank_similar,
    segment_descriptor,
)
from motionlib.vector_index import VectorIndex, build

DATA = data_dir()


def clips(seq, clip_frames):
    take = motionlib.read(DATA / "cmu" / "amc" / f"{seq}.amc", asf=DATA / "cmu" / "asf" / "13.asf")
    positions = motionlib.forward_kinematics(take)
    joints = motionlib.canonical_indices(take)
    scale = body_scale(positions, joints)
    rows = (DATA / "labels" / "mocap6" / "segments" / f"{seq}.csv").read_text().splitlines()[1:]
    names, descriptors = [], []
    margin = int(round(0.5 * take.fps))
    for row in rows:
        _, _, first, last, _, action = row.split(",")
        for start in range(int(first) - 1 + margin, int(last) - margin - clip_frames, clip_frames):
            names.append(action)
            descriptors.append(segment_descriptor(positions, joints, start, start + clip_frames,
                                                  fps=take.fps, scale=scale))
    return names, np.stack(descriptors)


def lists(index, count, nprobe):
    """Lists to scan: at least ``nprobe`` and enough to hold ``count`` vectors (as the
    service's index before faiss scanned); None, the index's own default."""
    if nprobe is None:
        return None
    return max(nprobe, -(-count * index.n_lists // len(index)))


def indexed_pool(index, query, pool, nprobe):
    """The ``pool`` members the vector index proposes for ``query``, as the service asks
    (``segmentation.similar.candidates.shortlist``: 4 x the shortlist of 20, at least 64)."""
    allowed = set(pool)
    vector = query[:PROFILE_ROWS].astype(np.float32).ravel()
    count = max(4 * 20, 64)
    while True:
        candidates = [int(i) for i in index.search(vector, count, nprobe=lists(index, count, nprobe))[0] if int(i) in allowed]
        if len(candidates) >= 20 or count >= len(allowed) + 1:
            return sorted(candidates)
        count *= 4


def evaluate(queries, library, leave_one_out, index=None, nprobe=None):
    """Per action: [top-1 hits, precision@5 sum, count, seconds]."""
    q_names, q_desc = queries
    l_names, l_desc = library
    stats = defaultdict(lambda: [0, 0.0, 0, 0.0])
    for q, action in enumerate(q_names):
        pool = [i for i in range(len(l_names)) if not (leave_one_out and i == q)]
        started = time.perf_counter()
        if index is not None:
            pool = indexed_pool(index, q_desc[q], pool, nprobe)
        found, _ = rank_similar(q_desc[q], l_desc[pool], k=5, shortlist=20)
        elapsed = time.perf_counter() - started
        labels = [l_names[pool[i]] for i in found]
        entry = stats[action]
        entry[0] += labels[0] == action
        entry[1] += labels.count(action) / len(labels)
        entry[2] += 1
        entry[3] += elapsed
    return stats


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--clip-seconds", type=float, default=1.0)
    args = parser.parse_args()
    if not DATA.is_dir():
        raise SystemExit(f"CMU data not found at {DATA.resolve()}")
    frames = int(round(args.clip_seconds * 120))
    lib = clips("13_29", frames)
    other = clips("13_30", frames)
    other = ([n for n in other[0] if n != "Jog"], other[1][[n != "Jog" for n in other[0]]])
    print(f"clips of {args.clip_seconds:g} s; descriptor {lib[1].shape[1]} x {lib[1].shape[2]}; "
          f"library 13_29: {len(lib[0])} clips\n")
    header = f"{'setting':<38} {'action':<16} {'clips':>5} {'top-1':>7} {'prec@5':>7} {'ms/query':>9}"
    print(header)
    print("-" * len(header))
    profiles = lib[1][:, :PROFILE_ROWS].reshape(len(lib[1]), -1)
    ids = np.arange(len(lib[1]))
    # The service's index at this size is one list (exact); 4 clips per list, scanning
    # from one list up, makes it probe.
    folder = Path(tempfile.mkdtemp(prefix="similar-labels-"))
    try:
        product = VectorIndex.open(folder / "product", build(folder / "product", ids, profiles))
        small = VectorIndex.open(folder / "small", build(folder / "small", ids, profiles,
                                                         n_lists=max(1, len(ids) // 4)))
        print_results(lib, other, product, small)
    finally:
        shutil.rmtree(folder, ignore_errors=True)


def print_results(lib, other, product, small):
    """Score each setting exactly, through the service's index and through the small one,
    and print a row per action and setting."""
    settings = [("13_29 leave-one-out", lib, True), ("13_30 -> 13_29", other, False)]
    results = []
    for title, queries, loo in settings:
        results += [(f"{title}", evaluate(queries, lib, loo)),
                    (f"{title} [index]", evaluate(queries, lib, loo, product)),
                    (f"{title} [index {small.n_lists} lists]",
                     evaluate(queries, lib, loo, small, nprobe=1))]
    for title, stats in results:
        total = [0, 0.0, 0, 0.0]
        for action in sorted(stats):
            hits, prec, n, seconds = stats[action]
            total = [a + b for a, b in zip(total, stats[action], strict=True)]
            print(f"{title:<38} {action:<16} {n:>5} {hits / n:>7.0%} {prec / n:>7.0%} "
                  f"{seconds / n * 1000:>9.1f}")
        hits, prec, n, seconds = total
        print(f"{title:<38} {'all':<16} {n:>5} {hits / n:>7.0%} {prec / n:>7.0%} "
              f"{seconds / n * 1000:>9.1f}\n")

