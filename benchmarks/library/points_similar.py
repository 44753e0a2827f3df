"""Similar clips and label suggestions on points of no known marker set: the vMCI takes.

Each top-level labelled segment of the 15 vMCI runs (``points/vmci``, 7 actions; the finer
``_part`` labels are left out) gets its ``motionlib.similarity.point_descriptor``. A segment's
label is then named from the others, as the service does:

- ``nearest``: the label of the single most similar segment (``rank_similar``, k = 1), what
  "find similar" shows first;
- ``vote of 5``: the label with most votes among the 5 most similar, a vote weighing 1 / d²
  (``segmentation.similar.suggestions.vote``), what a label suggestion is.

The pool is every segment of the *other* runs (leave one run out) or of the *other* subject
(leave one subject out: the settings of one performer never choose another's). ``chance`` is
the share of the most common label. Nothing here was tuned on these takes.

    .venv/bin/python -m benchmarks points-similar -- [--data ../shared/data]
"""

from __future__ import annotations

import argparse
import json
import time
from collections import Counter
from pathlib import Path

import numpy as np

import motionlib
from benchmarks.harness import data_dir
from motionlib import similarity

NEIGHBOURS = 5


def segments(folder: Path):
    """[(subject, run, label, descriptor)] of every top-level labelled vMCI segment, and the
    seconds spent describing them."""
    items, spent = [], 0.0
    for path in sorted(folder.glob("*.tsv")):
        take = motionlib.read(path)
        rows = json.loads(path.with_name(f"{path.stem}_manually_segmented.json").read_text())
        begin = time.perf_counter()
        points = similarity.seen_points(take.positions)
        scale = similarity.point_scale(points)
        for row in rows:
            start, stop = (row[k] - take.first_number for k in ("start index", "end index"))
            if row["label"].endswith("_part") or stop <= start:
                continue
            descriptor = similarity.point_descriptor(points, start, stop, fps=take.fps, scale=scale)
            items.append((path.stem.split("_")[0], path.stem, row["label"], descriptor))
        spent += time.perf_counter() - begin
    return items, spent


def named(query, pool, k):
    """The label ``k`` nearest of ``pool`` [(label, descriptor)] give ``query``."""
    order, distances = similarity.rank_similar(query, np.stack([d for _, d in pool]), k=k)
    votes = Counter()
    for i, d in zip(order, distances, strict=True):
        votes[pool[i][0]] += 1.0 / (d * d + 1e-9)
    return votes.most_common(1)[0][0]


def accuracy(items, held_out, k):
    right = 0
    for item in items:
        pool = [(label, d) for *key, label, d in items if held_out(key) != held_out(item[:2])]
        right += named(item[3], pool, k) == item[2]
    return right / len(items)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=data_dir())
    args = parser.parse_args(argv)
    folder = args.data / "points" / "vmci"
    if not folder.is_dir():
        print(f"{folder}: not found (the vMCI takes are under ../shared/data/points)")
        return 2
    items, spent = segments(folder)
    labels = Counter(label for _, _, label, _ in items)
    print(f"vMCI: {len(items)} segments of {len(labels)} actions in "
          f"{len({run for _, run, _, _ in items})} runs of {len({s for s, *_ in items})} subjects; "
          f"descriptors {len(items) / spent:.0f} per second (reading the takes not counted)")
    print(f"descriptor: {items[0][3].shape[0]} rows x {items[0][3].shape[1]} features")
    print()
    print(f"{'pool':<28}{'nearest':>10}{'vote of 5':>12}{'chance':>10}")
    chance = max(labels.values()) / len(items)
    for name, held_out in [("other runs", lambda key: key[1]), ("other subject", lambda key: key[0])]:
        print(f"{name:<28}{accuracy(items, held_out, 1):>10.2f}"
              f"{accuracy(items, held_out, NEIGHBOURS):>12.2f}{chance:>10.2f}")
    return 0

