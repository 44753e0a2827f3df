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


def fit_both(items, tolerance_s: float, fit_cuts, *, by_take: bool = False):
    """(cut model, label-aware model) fitted on ``items``: the cut learner as the curve
    fits it, then the frame model on their reviewed segments and the joint scorer. What
    they choose on their own (sharpness, cut source) is chosen on folds of ``items`` by
    subject, nested inside the by-subject split; by take (``by_take``) where the outer
    split is by take too (the single-subject CMU-86 sets)."""
    cut_model = fit_cuts(items, tolerance_s)
    examples = [labelling.FrameExample(i.example.samples, i.example.descriptors,
                                       i.example.n_frames, i.fps, reviewed(i.cuts, i.frames))
                for i in items]
    groups = [i.name if by_take else i.subject for i in items]
    frames = labelling.fit_frame_model(examples, groups=groups, tolerance_s=tolerance_s)
    joint = evidence.fit_label_cuts(cut_model, frames, [i.study for i in items], examples,
                                    [i.cuts for i in items], tolerance_s=tolerance_s,
                                    groups=groups)
    return cut_model, joint


def score_both(item, cut_model, joint, tolerance_s: float, scored) -> tuple:
    """([F1, edits, err, label acc] of the current learner, of the label-aware one, and
    of the decoded label changes taken as the cuts whatever the gate chose (tried, not
    shipped: the cut model's cuts where there is no frame model))."""
    post = None if joint.frames is None else labelling.posterior(joint.frames, item.example)
    rows = []
    current = adapt.cuts_in(item.study, cut_model)
    for cuts in (current, evidence.select(cut_model, joint, item.study, post)[0],
                 current if post is None else
                 evidence.decoded_cuts(joint.frames, post, item.fps)[0]):
        acc = float("nan") if post is None else label_accuracy(
            item.frames, cuts, labelling.propose(joint.frames, post, cuts, fps=item.fps))
        rows.append(np.append(scored(item, cuts, tolerance_s), acc))
    return tuple(rows)


def curve(label, ks, draws, pool_of, fit_cuts, scored) -> dict:
    """k -> (current [F1, edits, err, acc], label-aware [...], smallest, largest pool),
    the mean over the set's takes of the mean over draws (the curve's own draws)."""
    out = {"folds": {}}
    for k in ks:
        cur, new, sizes, dec = [], [], [], []
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
                dec.append(np.nanmean([r[2] for r in rows], axis=0))
        with np.errstate(all="ignore"), warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            out[k] = (np.nanmean(cur, axis=0), np.nanmean(new, axis=0), min(sizes), max(sizes))
            out.setdefault("decoded", {})[k] = np.nanmean(dec, axis=0)
            subjects = [i.subject for i in label.items]
            out["folds"][k] = {s: float(np.mean([n[0] for n, o in zip(new, subjects,
                                                                       strict=True) if o == s]))
                               for s in sorted(set(subjects))}
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
    clock = _Clock()
    cut_model = adapt.fit_cut_model(
        [adapt.Example(name=f"t{i}", cuts=cuts[j], fps=30.0, n_frames=takes[j][0].n_frames,
                       read=lambda j=j: takes[j][0], key=f"t{i}") for i, j in enumerate(many)],
        studies=_Stored({f"t{i}": studies[j] for i, j in enumerate(many)}))
    fit_cut = clock.lap()
    frames = labelling.fit_frame_model([examples[j] for j in many])
    joint = evidence.fit_label_cuts(cut_model, frames, [studies[j] for j in many],
                                    [examples[j] for j in many], [cuts[j] for j in many],
                                    tolerance_s=1.0)
    fit_labels = clock.lap()
    long_take, _ = synth.generate(seed=9, fps=30.0, duration=3600.0)
    clock.lap()
    study = adapt.study(long_take)
    candidates = clock.lap()
    post = labelling.posterior(joint.frames, long_take)
    found, _ = evidence.select(cut_model, joint, study, post)
    labelling.propose(joint.frames, post, found)
    labels = clock.lap()
    print(f"\n## Cost of the label-aware learner (synthetic 30 Hz skeleton takes; CPU "
          f"seconds of this process, one core, then wall seconds on the shared machine)\n"
          f"retrain from 50 reviewed 5-minute takes (their candidates and descriptors stored "
          f"as the service keeps them; each took {analysed:.1f} s wall to analyse once): "
          f"cut model {fit_cut[0]:.1f} / {fit_cut[1]:.1f} s, frame model and label-aware "
          f"scorer {fit_labels[0]:.1f} / {fit_labels[1]:.1f} s\n"
          f"detect a 60-minute take: candidates (the shipped detector's analysis) "
          f"{candidates[0]:.1f} / {candidates[1]:.1f} s, posterior, evidence, selection and "
          f"labels {labels[0]:.1f} / {labels[1]:.1f} s ({len(found)} cuts)", file=out)
    retrain = fit_cut[0] + fit_labels[0]
    detect = candidates[0] + labels[0]
    return {"retrain_s": retrain, "detect_s": detect}


class _Clock:
    """CPU and wall seconds since the last lap."""

    def __init__(self):
        self.cpu, self.wall = time.process_time(), time.perf_counter()

    def lap(self) -> tuple[float, float]:
        cpu, wall = time.process_time(), time.perf_counter()
        out = (cpu - self.cpu, wall - self.wall)
        self.cpu, self.wall = cpu, wall
        return out


class _Stored:
    def __init__(self, arrays):
        self.arrays = arrays

    def load(self, example_key, study_key):
        return self.arrays.get(example_key)

    def save(self, example_key, study_key, arrays):
        self.arrays[example_key] = arrays


# ---- tables ---------------------------------------------------------------------------------


def print_curves(sets, ks, draws, pool_of, fit_cuts, scored, baseline, out) -> dict:
    """The by-subject curve of both learners in one table; returns name -> curve."""
    chosen = [s for s in sets if s.by_subject and s.items]
    print("\n## Label-aware learner by subject (out of sample: reviewed takes of other "
          "subjects only; motionlib.labelling)\nF1 at the set's tolerance / review edits "
          "per true cut / median placement error (s) / label accuracy of the proposed "
          "labels (share of the true labelled frames whose segment's proposal is their "
          "label; '-' where no label model exists); mean over the set's takes of the mean "
          f"over {draws} seeded draws (the curve's). 'current' is the shipped cut learner "
          "(its segments labelled by the same frame model), 'labels' the label-aware "
          "learner (the cut source its gate chose on the reviewed takes), 'decoded*' "
          "(tried, not shipped) the decoded label changes taken as the cuts in every "
          "draw, whatever the gate chose.", file=out)
    print(f"{'set':<10}{'method':<22}{'F1':>7}{'edits':>7}{'err s':>7}{'label':>7}",
          file=out)
    curves = {}
    for label in chosen:
        zs, rp = baseline(label)
        got = curve(label, ks, draws, pool_of, fit_cuts, scored)
        curves[label.name] = (got, zs)
        print(f"{label.name:<10}{'ruptures':<22}" + _cells([*rp, np.nan]), file=out)
        print(f"{label.name:<10}{'zero-shot (k=0)':<22}" + _cells(got[0][0]), file=out)
        for k in ks[1:]:
            cur, new, lo, hi = got[k]
            note = f"k={k}" + (f" (<={hi})" if hi < k else "")
            print(f"{label.name:<10}{note + ' current':<22}" + _cells(cur), file=out)
            print(f"{label.name:<10}{note + ' labels':<22}" + _cells(new), file=out)
            print(f"{label.name:<10}{note + ' decoded*':<22}" + _cells(got['decoded'][k]),
                  file=out)
    if len(curves) > 1:
        for k in ks:
            for j, tag in ((0, "current"), (1, "labels")):
                if k == 0 and j:
                    continue
                mean = np.nanmean([c[0][k][j] for c in curves.values()], axis=0)
                print(f"{'mean':<10}{(f'k={k} ' + tag) if k else 'zero-shot (k=0)':<22}" +
                      _cells(mean), file=out)
    return curves


def _cells(row) -> str:
    return "".join(f"{v:>7.2f}" if np.isfinite(v) else f"{'-':>7}" for v in row)


def convention(sets, fit_cuts, scored, out) -> float | None:
    """Convention-following of the label-aware learner on the CMU-86 takes both labelled:
    taught one convention's other takes, scored against both (F1 at 1 s)."""
    named = {s.name: s for s in sets}
    kr, bk = named.get("cmu86 Krüger"), named.get("cmu86 Baak")
    if not kr or not bk or not kr.items or not bk.items:
        return None
    kr_items, bk_items = {i.name: i for i in kr.items}, {i.name: i for i in bk.items}
    print("\n## Convention-following of the label-aware learner (CMU-86, within subject, "
          "by take; the four-channel takes, as the shipped learner's table: the shared data "
          "has a full skeleton for 86_01 only)\ntake    taught    vs Krüger  vs Baak  "
          "taught-other  (current learner's taught-other)", file=out)
    gains, old = [], []
    for name in sorted(set(kr_items) & set(bk_items)):
        held_k, held_b = kr_items[name], bk_items[name]
        for taught, label in (("Krüger", kr), ("Baak", bk)):
            cut_model, joint = fit_both([i for i in label.items if i.name != name], 1.0,
                                        fit_cuts, by_take=True)
            post = None if joint.frames is None else labelling.posterior(
                joint.frames, (held_k if taught == "Krüger" else held_b).example)
            found = evidence.select(cut_model, joint, held_k.study, post)[0]
            current = adapt.cuts_in(held_k.study, cut_model)
            sign = 1 if taught == "Krüger" else -1
            fk, fb = scored(held_k, found, 1.0)[0], scored(held_b, found, 1.0)[0]
            ck, cb = scored(held_k, current, 1.0)[0], scored(held_b, current, 1.0)[0]
            gains.append(sign * (fk - fb))
            old.append(sign * (ck - cb))
            print(f"{name:<8}{taught:<8}{fk:>11.2f}{fb:>9.2f}{gains[-1]:>+14.2f}"
                  f"{old[-1]:>+10.2f}", file=out)
    mean = float(np.mean(gains))
    print(f"{'mean':<16}{'':>20}{mean:>+14.2f}{np.mean(old):>+10.2f}", file=out)
    return mean


TARGETS = {"utkinect": (0.75, 0.8, 0.75), "vmci": (0.85, None, None)}
TARGET_K, TARGET_CONVENTION, TARGET_DETECT_S, TARGET_RETRAIN_S = 5, 0.10, 5.0, 10.0


def targets(curves: dict, conv: float | None, costs: dict, out) -> None:
    """The label-aware learner against its targets (at k = TARGET_K, by subject)."""
    print("\n## Targets of the label-aware learner (by subject, k=5)", file=out)
    for name, (got, _) in curves.items():
        goal = TARGETS.get(name)
        f1, edits, _, acc = got[TARGET_K][1]
        folds = got["folds"][TARGET_K]
        worse = [k for k in got if k not in ("folds", "decoded", 0)
                 and got[k][1][0] < got[0][0][0] - 1e-9]
        cells = [f"F1 {f1:.2f}", f"edits {edits:.2f}", f"label accuracy {acc:.2f}",
                 "F1 per held-out subject " + " ".join(f"{s}:{v:.2f}" for s, v in folds.items())]
        if goal:
            cells.append(f"F1 >= {goal[0]}: {'met' if f1 >= goal[0] else 'NOT met'}")
            if name == "vmci":
                ok = min(folds.values()) >= goal[0]
                cells.append(f"every fold: {'met' if ok else 'NOT met'}")
            if goal[1] is not None:
                cells.append(f"edits <= {goal[1]}: {'met' if edits <= goal[1] else 'NOT met'}")
                cells.append(f"label accuracy >= {goal[2]}: "
                             f"{'met' if acc >= goal[2] else 'NOT met'}")
        cells.append("never below zero-shot F1: " + (
            "met" if not worse else "NOT met at k=" + ",".join(map(str, worse))))
        print(f"{name:<10}" + "; ".join(cells), file=out)
    if conv is not None:
        print(f"convention-following gain {conv:+.2f} (>= +{TARGET_CONVENTION}: "
              f"{'met' if conv >= TARGET_CONVENTION else 'NOT met'})", file=out)
    if costs:
        print(f"detect a 60-minute take {costs['detect_s']:.1f} s (<= {TARGET_DETECT_S:g}: "
              f"{'met' if costs['detect_s'] <= TARGET_DETECT_S else 'NOT met'}); retrain "
              f"from 50 takes {costs['retrain_s']:.1f} s (<= {TARGET_RETRAIN_S:g}: "
              f"{'met' if costs['retrain_s'] <= TARGET_RETRAIN_S else 'NOT met'})", file=out)
