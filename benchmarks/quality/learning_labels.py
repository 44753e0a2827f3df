"""The label-aware learner in the ``learning-curve`` benchmark (``motionlib.labelling``).

Every labelled take also has its labelled stretches (``raw_segments``: the set's own
action intervals, in take frames). A reviewed take is seen as a reviewer leaves it: the
segments between its human cuts, each carrying the label that covers most of its frames
(or none). For every scored take and ``k``, the same seeded draws of reviewed takes of
*other* subjects as the learning curve fit the current cut learner and, on them, the
frame model and the label-aware scorer; both are scored on the take in the same run:
F1 at the set's tolerance, review edits per true cut, median placement error and label
accuracy (share of the true labelled stretches' frames whose segment's proposed label is
the true one; the current learner's segments get their proposals from the same frame
model).
"""

from __future__ import annotations

import csv
import json
import time
import warnings

import numpy as np

from motionlib import adapt, labelling
from motionlib.labelling import evidence

# ---- labelled stretches of each set, in take frames (end exclusive) -------------------------


def raw_segments(root, set_name: str, name: str, take) -> list[tuple[int, int, str]]:
    """The labelled stretches of take ``name`` of ``set_name``; [] for a set without."""
    loader = RAW.get(set_name)
    return sorted(loader(root, name, take)) if loader else []


def _utkinect(root, name, take):
    with open(root / "points" / "utkinect" / "labels.csv", newline="") as fh:
        return [(int(r["start_frame_id"]) - take.first_number,
                 int(r["end_frame_id"]) + 1 - take.first_number, r["action"])
                for r in csv.DictReader(fh) if r["take"] == name]


def _vmci(root, name, take):
    with open(root / "points" / "vmci" / f"{name}_manually_segmented.json") as fh:
        rows = json.load(fh)
    parts = [r for r in rows if r["label"].endswith("_part")]
    out = [(r["start index"], r["end index"], r["label"][:-5]) for r in parts]
    for r in rows:
        if r["label"].endswith("_part"):
            continue
        if not any(p[0] >= r["start index"] - 1 and p[1] <= r["end index"] + 1 for p in out):
            out.append((r["start index"], r["end index"], r["label"]))
    return [(s - take.first_number, e + 1 - take.first_number, lab) for s, e, lab in out]


def _kruger(root, name, take):
    with open(root / "labels" / "cmu86_kruger2017" / f"{name}.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    ends = [int(r["end_mid"]) for r in rows[:-1]] + [take.n_frames]
    starts = [0] + ends[:-1]
    return [(s, e, r["label"]) for s, e, r in zip(starts, ends, rows, strict=True)]


def _baak(root, name, take):
    with open(root / "labels" / "cmu86_baak" / "intervals.csv", newline="") as fh:
        return [(int(r["start_frame"]) - 1, int(r["end_frame"]), r["class"])
                for r in csv.DictReader(fh) if r["take"] == name]


RAW = {"utkinect": _utkinect, "vmci": _vmci, "cmu86 Krüger": _kruger, "cmu86 Baak": _baak}


def per_frame(raw, n_frames: int) -> np.ndarray:
    """(n_frames,) each frame's true label ("" outside every stretch; later stretches win)."""
    out = np.full(n_frames, "", dtype=object)
    for start, end, label in raw:
        out[max(0, start):max(0, min(end, n_frames))] = label
    return out


LABELLED_SHARE = 0.25


def reviewed(cuts, truth_frames: np.ndarray) -> list[tuple[int, int, str]]:
    """The segments a reviewer leaves between ``cuts``: each labelled with the label
    covering most of its labelled frames ("" when under ``LABELLED_SHARE`` of its frames
    carry a label: the reviewer leaves it unlabelled)."""
    n = len(truth_frames)
    bounds = np.concatenate([[0], np.sort(np.asarray(cuts, dtype=np.int64)), [n]])
    out = []
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        if hi <= lo:
            continue
        inside = truth_frames[lo:hi].astype(str)
        named = inside[inside != ""]
        if len(named) < LABELLED_SHARE * len(inside):
            out.append((int(lo), int(hi), ""))
            continue
        values, counts = np.unique(named, return_counts=True)
        out.append((int(lo), int(hi), str(values[np.argmax(counts)])))
    return out


def label_accuracy(truth_frames: np.ndarray, cuts, proposals) -> float:
    """Share of the labelled frames whose segment's proposed label is theirs."""
    labelled = truth_frames != ""
    if not labelled.any():
        return float("nan")
    bounds = np.concatenate([[0], np.sort(np.asarray(cuts, dtype=np.int64)),
                             [len(truth_frames)]])
    guess = np.full(len(truth_frames), None, dtype=object)
    for (lo, hi), (label, _) in zip(zip(bounds[:-1], bounds[1:], strict=True), proposals,
                                    strict=True):
        guess[lo:hi] = label or ""
    return float(np.mean(guess[labelled] == truth_frames[labelled]))


# ---- fitting and scoring --------------------------------------------------------------------


def fit_both(items, tolerance_s: float, fit_cuts):
    """(cut model, label-aware model) fitted on ``items``: the cut learner as the curve
    fits it, then the frame model on their reviewed segments and the joint scorer."""
    cut_model = fit_cuts(items, tolerance_s)
    examples = [labelling.FrameExample(i.example.samples, i.example.descriptors,
                                       i.example.n_frames, i.fps, reviewed(i.cuts, i.frames))
                for i in items]
    frames = labelling.fit_frame_model(examples)
    joint = evidence.fit_label_cuts(cut_model, frames, [i.study for i in items], examples,
                                    [i.cuts for i in items], tolerance_s=tolerance_s)
    return cut_model, joint


def score_both(item, cut_model, joint, tolerance_s: float, scored) -> tuple:
    """([F1, edits, err, label acc] of the current learner, of the label-aware one)."""
    post = None if joint.frames is None else labelling.posterior(joint.frames, item.example)
    rows = []
    for cuts in (adapt.cuts_in(item.study, cut_model),
                 evidence.select(cut_model, joint, item.study, post)[0]):
        acc = float("nan") if post is None else label_accuracy(
            item.frames, cuts, labelling.propose(joint.frames, post, cuts))
        rows.append(np.append(scored(item, cuts, tolerance_s), acc))
    return tuple(rows)


def curve(label, ks, draws, pool_of, fit_cuts, scored) -> dict:
    """k -> (current [F1, edits, err, acc], label-aware [...], smallest, largest pool),
    the mean over the set's takes of the mean over draws (the curve's own draws)."""
    out = {}
    for k in ks:
        cur, new, sizes = [], [], []
        for t, item in enumerate(label.items):
            pool = pool_of(label, item)
            kk = min(k, len(pool))
            sizes.append(kk)
            rows = []
            for d in range(draws if kk else 1):
                rng = np.random.default_rng([t, k, d])
                chosen = [pool[i] for i in rng.choice(len(pool), kk, replace=False)]
                if kk == 0:
                    zero = adapt.CutModel.zero_shot(label.tolerance_s)
                    rows.append(score_both(item, zero, evidence.LabelCutModel.identity(),
                                           label.tolerance_s, scored))
                else:
                    rows.append(score_both(item, *fit_both(chosen, label.tolerance_s,
                                                           fit_cuts),
                                           label.tolerance_s, scored))
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)
                cur.append(np.nanmean([r[0] for r in rows], axis=0))
                new.append(np.nanmean([r[1] for r in rows], axis=0))
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            out[k] = (np.nanmean(cur, axis=0), np.nanmean(new, axis=0), min(sizes), max(sizes))
    return out


def cost(out) -> dict:
    """Seconds to detect a 60-minute take with a label-aware model (candidates, frame
    posterior, evidence, labels), and to retrain it from 50 reviewed 5-minute takes
    (their candidates and descriptors stored, as the service keeps them)."""
    from motionlib import synth

    takes = [synth.generate(seed=s, fps=30.0, duration=300.0) for s in range(3)]
    started = time.perf_counter()
    studies = [adapt.study(t) for t, _ in takes]
    examples = [labelling.frame_example(t, segs) for t, segs in takes]
    analysed = (time.perf_counter() - started) / len(takes)
    cuts = [np.asarray([s for s, _, _ in segs[1:]]) for _, segs in takes]
    many = [i % 3 for i in range(50)]
    started = time.perf_counter()
    cut_model = adapt.fit_cut_model(
        [adapt.Example(name=f"t{i}", cuts=cuts[j], fps=30.0, n_frames=takes[j][0].n_frames,
                       read=lambda j=j: takes[j][0], key=f"t{i}") for i, j in enumerate(many)],
        studies=_Stored({f"t{i}": studies[j] for i, j in enumerate(many)}))
    frames = labelling.fit_frame_model([examples[j] for j in many])
    joint = evidence.fit_label_cuts(cut_model, frames, [studies[j] for j in many],
                                    [examples[j] for j in many], [cuts[j] for j in many],
                                    tolerance_s=1.0)
    retrain = time.perf_counter() - started
    long_take, _ = synth.generate(seed=9, fps=30.0, duration=3600.0)
    started = time.perf_counter()
    study = adapt.study(long_take)
    post = labelling.posterior(joint.frames, long_take)
    found, _ = evidence.select(cut_model, joint, study, post)
    labelling.propose(joint.frames, post, found)
    detect = time.perf_counter() - started
    print(f"\n## Cost of the label-aware learner (synthetic 30 Hz skeleton takes, one core)\n"
          f"retrain from 50 reviewed 5-minute takes (their candidates and descriptors "
          f"stored; each took {analysed:.1f} s to analyse once): {retrain:.1f} s\n"
          f"detect a 60-minute take with the model (candidates, posterior, evidence, "
          f"labels): {detect:.1f} s ({len(found)} cuts)", file=out)
    return {"retrain_s": retrain, "detect_s": detect}


class _Stored:
    def __init__(self, arrays):
        self.arrays = arrays

    def load(self, example_key, study_key):
        return self.arrays.get(example_key)

    def save(self, example_key, study_key, arrays):
        self.arrays[example_key] = arrays
