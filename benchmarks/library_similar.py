"""Similar-clip search on the labelled CMU takes: does the nearest clip show the same action?

The mocap6 takes 13_29 and 13_30 (same actor, human labels) are cut into consecutive clips
inside each labelled action (half a second trimmed at each end, since the labels mark
10 fps blocks). Two settings, one row per action and setting:

- ``13_29 leave-one-out``: each 13_29 clip searched among the other 13_29 clips;
- ``13_30 -> 13_29``: each 13_30 clip searched in the 13_29 library (13_30's Jog has no
  counterpart in 13_29 and is left out).

Columns: clips, share whose nearest clip is the same action (top-1), mean share of the
same action among the 5 nearest (precision@5; capped when an action has fewer than five
other clips, e.g. 13_29's JumpJack has one), and search time per query.

    .venv/bin/python benchmarks/library_similar.py [--clip-seconds 1.0]
"""

import argparse
import sys
import time
from collections import defaultdict
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

import motionlib  # noqa: E402
from motionlib.benchdata import data_dir  # noqa: E402
from motionlib.similarity import body_scale, rank_similar, segment_descriptor  # noqa: E402

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


def evaluate(queries, library, leave_one_out):
    """Per action: [top-1 hits, precision@5 sum, count, seconds]."""
    q_names, q_desc = queries
    l_names, l_desc = library
    stats = defaultdict(lambda: [0, 0.0, 0, 0.0])
    for q, action in enumerate(q_names):
        pool = [i for i in range(len(l_names)) if not (leave_one_out and i == q)]
        started = time.perf_counter()
        found, _ = rank_similar(q_desc[q], l_desc[pool], k=5)
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
    header = f"{'setting':<22} {'action':<16} {'clips':>5} {'top-1':>7} {'prec@5':>7} {'ms/query':>9}"
    print(header)
    print("-" * len(header))
    for title, stats in (("13_29 leave-one-out", evaluate(lib, lib, True)),
                         ("13_30 -> 13_29", evaluate(other, lib, False))):
        total = [0, 0.0, 0, 0.0]
        for action in sorted(stats):
            hits, prec, n, seconds = stats[action]
            total = [a + b for a, b in zip(total, stats[action], strict=True)]
            print(f"{title:<22} {action:<16} {n:>5} {hits / n:>7.0%} {prec / n:>7.0%} "
                  f"{seconds / n * 1000:>9.1f}")
        hits, prec, n, seconds = total
        print(f"{title:<22} {'all':<16} {n:>5} {hits / n:>7.0%} {prec / n:>7.0%} "
              f"{seconds / n * 1000:>9.1f}\n")


if __name__ == "__main__":
    main()
