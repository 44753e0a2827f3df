"""How a studio's cut model learns: ``python -m benchmarks learning-curve``.

Each labelled set is one convention. For every scored take, ``k`` reviewed takes are
drawn (``DRAWS`` seeded draws) and a model is fitted on them (``motionlib.adapt``,
at the set's tolerance) and scored on the take: F1 at the set's tolerance, review
edits per true cut and the median placement error, beside the zero-shot detector
(k = 0, which is the model's prior) and ruptures in the same run.

- *By subject* (out of sample): the reviewed takes come from other subjects only, never
  the scored one (UTKinect, vMCI). Where fewer than ``k`` such takes exist, ``k`` is
  capped and the table says so.
- *Within subject, by take*: sets of a single subject (mocap6, Krüger's and Baak's
  CMU-86 labels, HDM05) cannot be split by subject; their curve draws other takes of the
  same subject and is printed apart, marked as not out of sample by subject.

Then convention-following (Krüger's and Baak's labels of the same subject-86 takes:
a model taught one convention, scored against both, on each take it did not learn
from), the oracle ceiling (``ceiling``: what the best choice among each take's
candidates scores against its own labels, to tell a candidate set that lacks the cuts
from a scorer that cannot find them; not a result), the poisoning case (3 of the
reviewed takes under- or over-cut by one annotator), labellings tried and not shipped
(``learning_tried``), and whether the issue's targets are met. Every take's candidates are
computed once (``adapt.study``) and every model detects from them (``adapt.cuts_in``),
so the whole run takes minutes. The learner's fixed settings were not chosen on any
figure here (``docs/detector/adaptation.md``).
"""

from __future__ import annotations

import io
import os
import sys
import time
import warnings
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from benchmarks.quality import ceiling, data, learning_labels, learning_tried
from motionlib import adapt
from motionlib import labelling as frame_labels

KS = (0, 1, 3, 5, 10)
DRAWS = 5
POISONED = 3  # of POISON_K reviewed takes
POISON_K = 10
TARGET_F1, TARGET_EDITS, TARGET_K = 0.92, 0.4, 5
TARGET_CONVENTION, TARGET_POISON = 0.15, 0.05
# How every fit here labels the candidates (``adapt.fit_cut_model``'s ``labels``): the
# shipped labelling, unless ``labelled_as`` tries another.
LABELS = adapt.matched_labels


@dataclass
class Item:
    """A labelled take with what every model reads of it, computed once."""

    name: str
    subject: str
    fps: float
    truth: np.ndarray  # (n, 3) windows
    study: dict | None
    ruptures: np.ndarray
    example: object = None  # labelling.FrameExample: the take's descriptors
    frames: np.ndarray | None = None  # (n_frames,) true label per frame, "" unlabelled

    @property
    def cuts(self) -> np.ndarray:
        """The take's human cuts as a reviewer leaves them: the windows' middles."""
        return np.unique(self.truth[:, 1])


@dataclass
class LabelSet:
    name: str
    tolerance_s: float
    by_subject: bool
    items: list[Item] = field(default_factory=list)


def _item(name, subject, take, truth, tolerance_s, ruptures, *, root=None,
          set_name="") -> Item:
    raw = learning_labels.raw_segments(root, set_name, name, take)
    return Item(name, subject, float(take.fps), np.asarray(truth, dtype=np.int64),
                adapt.study(take), np.asarray(ruptures(take, tolerance_s)),
                frame_labels.frame_example(take, raw),
                learning_labels.per_frame(raw, int(take.n_frames)))


def load_sets(root: Path, log) -> list[LabelSet]:
    """Every labelled set with its takes read and studied once."""
    from benchmarks.quality import points as points_quality
    from benchmarks.quality.bench import ruptures_kernel

    rot = lambda take, _tol: ruptures_kernel(take)  # noqa: E731
    takes = data.discover(root, channels=True)[0]
    sets = [LabelSet("mocap6", 1.0, False), LabelSet("cmu86 Krüger", 1.0, False),
            LabelSet("cmu86 Baak", 1.0, False)]
    for labelled in takes:
        if labelled.source == "mocap6":
            target = sets[0]
        elif labelled.source == "kruger2017" and labelled.kind == "channels":
            target = sets[1]  # one view per take: the four channels every 86 take has
        else:
            continue
        target.items.append(_item(labelled.name, labelled.name.split("_")[0],
                                  labelled.read(), labelled.truth, 1.0, rot, root=root,
                                  set_name=target.name))
    for labelled in data.baak_takes(root):
        sets[2].items.append(_item(labelled.name, "86", labelled.read(), labelled.truth,
                                   1.0, rot, root=root, set_name=sets[2].name))
    if (root / "points").is_dir():
        for name, loader in points_quality.SETS.items():
            found = loader(root)
            subjects = {t.subject for t in found.takes}
            label = LabelSet(name, found.tolerance_s, len(subjects) > 1)
            for t in found.takes:
                label.items.append(_item(t.name, t.subject, t.read(), t.truth,
                                         found.tolerance_s, points_quality.ruptures_cuts,
                                         root=root, set_name=name))
            sets.append(label)
    print(f"read and studied {sum(len(s.items) for s in sets)} takes", file=log)
    return sets


_FITTED: dict = {}


def fit(items: list[Item], tolerance_s: float, cuts=None) -> adapt.CutModel:
    """A model fitted on ``items`` (their human cuts, or ``cuts``) through the public
    API, every take's candidates standing in for it (``studies``). A fit on the human
    cuts is kept: the label-aware tables refit the same draws."""
    key = (tuple(id(i) for i in items), tolerance_s)
    if cuts is None and key in _FITTED:
        return _FITTED[key]
    model = _fit(items, tolerance_s, cuts)
    if cuts is None:
        _FITTED[key] = model
    return model


def _fit(items: list[Item], tolerance_s: float, cuts=None) -> adapt.CutModel:
    studies = Known({f"{item.subject}/{item.name}": item.study for item in items})
    examples = []
    for i, item in enumerate(items):
        key = f"{item.subject}/{item.name}"
        examples.append(adapt.Example(name=item.name, cuts=item.cuts if cuts is None
                                      else cuts[i], fps=item.fps,
                                      n_frames=int(item.study["n_frames"]),
                                      read=_unread(item.name), key=key))
    return adapt.fit_cut_model(examples, studies=studies, tolerance_s=tolerance_s,
                               labels=LABELS)


class Known:
    """``adapt.Studies`` holding every take's candidates, made with the zero-shot settings
    as every fit here asks."""

    def __init__(self, arrays: dict):
        self.arrays = arrays

    def load(self, example_key, study_key):
        return self.arrays.get(example_key)

    def save(self, example_key, study_key, arrays):
        self.arrays[example_key] = arrays


def _unread(name):
    def read():
        raise AssertionError(f"{name}: its stored candidates should stand in for it")
    return read


def scored(item: Item, found, tolerance_s: float) -> np.ndarray:
    s = adapt.score_cuts(found, item.truth, fps=item.fps, tolerance_s=tolerance_s)
    return np.array([s["f1"], s["edits_per_cut"], s["median_error_s"]])


def _pool(label: LabelSet, item: Item) -> list[Item]:
    if label.by_subject:
        return [o for o in label.items if o.subject != item.subject]
    return [o for o in label.items if o is not item]


def curve(label: LabelSet) -> dict:
    """k -> (mean [F1, edits, error] over the set's takes, smallest pool, largest pool);
    and "best count": at k = TARGET_K, the mean over takes of the models' F1 with the
    count chosen against the take's labels (``ceiling.best_count``, an oracle)."""
    out = {}
    zero = adapt.CutModel.zero_shot(label.tolerance_s)
    counted = []
    for k in KS:
        per_take, sizes = [], []
        for t, item in enumerate(label.items):
            pool = _pool(label, item)
            kk = min(k, len(pool))
            sizes.append(kk)
            if kk == 0:
                per_take.append(scored(item, adapt.cuts_in(item.study, zero),
                                       label.tolerance_s))
                continue
            rows = []
            for d in range(DRAWS):
                rng = np.random.default_rng([t, k, d])
                chosen = [pool[i] for i in rng.choice(len(pool), kk, replace=False)]
                model = fit(chosen, label.tolerance_s)
                rows.append(scored(item, adapt.cuts_in(item.study, model), label.tolerance_s))
                if k == TARGET_K:
                    counted.append((t, ceiling.best_count(
                        item.study, item.truth, model, fps=item.fps,
                        tolerance_s=label.tolerance_s)))
            with np.errstate(all="ignore"), warnings.catch_warnings():
                warnings.simplefilter("ignore", RuntimeWarning)  # no match: NaN error
                per_take.append(np.nanmean(rows, axis=0))
        out[k] = (np.nanmean(per_take, axis=0), min(sizes), max(sizes))
    if counted:
        takes = np.asarray([t for t, _ in counted])
        values = np.asarray([v for _, v in counted])
        out["best count"] = float(np.mean([values[takes == t].mean()
                                           for t in np.unique(takes)]))
    return out


def baseline(label: LabelSet) -> tuple[np.ndarray, np.ndarray]:
    """Mean [F1, edits, error] of zero-shot (the default detector) and ruptures."""
    zero = adapt.CutModel.zero_shot(label.tolerance_s)
    zs = [scored(i, adapt.cuts_in(i.study, zero), label.tolerance_s) for i in label.items]
    rp = [scored(i, i.ruptures, label.tolerance_s) for i in label.items]
    return np.nanmean(zs, axis=0), np.nanmean(rp, axis=0)


def print_curves(sets: list[LabelSet], by_subject: bool, out) -> dict:
    chosen = [s for s in sets if s.by_subject == by_subject and s.items]
    if by_subject:
        print("\n## Learning curve by subject (out of sample: reviewed takes of other "
              "subjects only)", file=out)
    else:
        print("\n## Learning curve within subject, by take — NOT out of sample by subject "
              "(single-subject sets: the reviewed takes are other takes of the scored "
              "take's performer)", file=out)
    print("F1 at the set's tolerance / review edits per true cut / median placement error "
          "(s); mean over the set's takes of the mean over draws. k capped at the "
          "reviewed takes there are: 'k=10 (<=8)' means 8.", file=out)
    head = f"{'set':<14}{'takes':>6}{'tol s':>6}  {'method':<16}"
    print(head + "".join(f"{'F1':>7}{'edits':>7}{'err s':>7}" for _ in range(1)), file=out)
    curves = {}
    for label in chosen:
        zs, rp = baseline(label)
        got = curve(label)
        curves[label.name] = (got, zs)
        lead = f"{label.name:<14}{len(label.items):>6}{label.tolerance_s:>6g}  "
        print(lead + f"{'ruptures':<16}" + _cells(rp), file=out)
        print(lead + f"{'zero-shot':<16}" + _cells(zs), file=out)
        for k in KS[1:]:
            row, lo, hi = got[k]
            note = f"k={k}" + (f" (<={hi})" if hi < k else "") + (
                f" [{lo} for some]" if lo < hi else "")
            print(lead + f"{note:<16}" + _cells(row), file=out)
    if len(chosen) > 1:
        print(f"{'mean':<14}{'':>6}{'':>6}  {'zero-shot':<16}" +
              _cells(np.mean([c[1] for c in curves.values()], axis=0)), file=out)
        for k in KS[1:]:
            mean = np.mean([c[0][k][0] for c in curves.values()], axis=0)
            print(f"{'mean':<14}{'':>6}{'':>6}  {f'k={k}':<16}" + _cells(mean), file=out)
    return curves


def _cells(row) -> str:
    return "".join(f"{v:>7.2f}" if np.isfinite(v) else f"{'-':>7}" for v in row)


def convention(sets: list[LabelSet], out) -> float | None:
    """Mean over held-out takes and both directions of F1(taught) - F1(other)."""
    named = {s.name: s for s in sets}
    kr, bk = named.get("cmu86 Krüger"), named.get("cmu86 Baak")
    if not kr or not bk or not kr.items or not bk.items:
        print("\nconvention-following: needs both CMU-86 labellings", file=out)
        return None
    kr_items, bk_items = {i.name: i for i in kr.items}, {i.name: i for i in bk.items}
    common = sorted(set(kr_items) & set(bk_items))
    print("\n## Convention-following on the CMU-86 takes both labelled (within subject 86, "
          "by take)\nA model taught with one convention's other takes, scored on the held-out "
          "take against both conventions (F1 at 1 s).", file=out)
    print(f"{'take':<8}{'taught':<8}{'vs Krüger':>11}{'vs Baak':>9}{'taught-other':>14}"
          f"{'zero-shot K/B':>15}", file=out)
    gains = []
    for name in common:
        held_k, held_b = kr_items[name], bk_items[name]
        zero = adapt.cuts_in(held_k.study, adapt.CutModel.zero_shot())
        zk, zb = (scored(h, zero, 1.0)[0] for h in (held_k, held_b))
        for taught, label in (("Krüger", kr), ("Baak", bk)):
            model = fit([i for i in label.items if i.name != name], 1.0)
            found = adapt.cuts_in(held_k.study, model)
            fk, fb = scored(held_k, found, 1.0)[0], scored(held_b, found, 1.0)[0]
            gain = fk - fb if taught == "Krüger" else fb - fk
            gains.append(gain)
            print(f"{name:<8}{taught:<8}{fk:>11.2f}{fb:>9.2f}{gain:>+14.2f}"
                  f"{f'{zk:.2f}/{zb:.2f}':>15}", file=out)
    mean = float(np.mean(gains))
    print(f"{'mean':<16}{'':>20}{mean:>+14.2f}", file=out)
    return mean


def print_ceiling(sets: list[LabelSet], curves: dict, out) -> None:
    """The oracle ceiling per set (``benchmarks/quality/ceiling.py``) beside the zero-shot
    detector's recall and the curve's model at k = TARGET_K."""
    print("\n## Ceiling — an ORACLE, not a result: the best subset of each take's candidates "
          "chosen with that take's own labels (benchmarks/quality/ceiling.py)", file=out)
    print("Per set, mean over takes: candidates and true cuts per take; recall of the "
          "zero-shot cuts and of all candidates (a true cut with a candidate within the "
          "set's tolerance); the oracle subset's F1 and review edits per true cut; the "
          f"curve's k={TARGET_K} models (by subject or within subject, as above): F1, and "
          "F1 with their own ranking cut at the count the labels make best (best count).",
          file=out)
    print(f"{'set':<14}{'split':>8}{'takes':>6}{'tol s':>6}{'cands':>7}{'true':>6}"
          f"{'rec zs':>8}{'rec cand':>9}{'ceil F1':>9}{'ceil ed':>9}"
          f"{f'k={TARGET_K} F1':>8}{'best count':>11}", file=out)
    for label in sorted((s for s in sets if s.items), key=lambda s: not s.by_subject):
        zero = adapt.CutModel.zero_shot(label.tolerance_s)
        zs = [adapt.score_cuts(adapt.cuts_in(i.study, zero), i.truth, fps=i.fps,
                               tolerance_s=label.tolerance_s)["recall"] for i in label.items]
        top = np.mean([ceiling.take_ceiling(i.study, i.truth, fps=i.fps,
                                            tolerance_s=label.tolerance_s)
                       for i in label.items], axis=0)
        sizes = np.mean([[len(i.study["stages"]) if i.study else 0,
                          len(i.cuts)] for i in label.items], axis=0)
        got = curves[label.name][0]
        learnt = f"{got[TARGET_K][0][0]:>8.2f}{got.get('best count', np.nan):>11.2f}" \
            if got[TARGET_K][1] > 0 else f"{'-':>8}{'-':>11}"
        print(f"{label.name:<14}{'subject' if label.by_subject else 'within':>8}"
              f"{len(label.items):>6}{label.tolerance_s:>6g}{sizes[0]:>7.0f}{sizes[1]:>6.1f}"
              f"{np.mean(zs):>8.2f}{top[0]:>9.2f}{top[1]:>9.2f}{top[2]:>9.2f}{learnt}",
              file=out)
    conv = _convention_ceiling(sets)
    if conv is not None:
        print(f"convention-following, oracle: the oracle subset for one convention's labels "
              f"scored against both, mean F1(taught) - F1(other) {conv:+.2f}", file=out)


def _convention_ceiling(sets: list[LabelSet]) -> float | None:
    named = {s.name: s for s in sets}
    kr, bk = named.get("cmu86 Krüger"), named.get("cmu86 Baak")
    if not kr or not bk:
        return None
    kr_items, bk_items = {i.name: i for i in kr.items}, {i.name: i for i in bk.items}
    gains = []
    for name in sorted(set(kr_items) & set(bk_items)):
        pair = (kr_items[name], bk_items[name])
        for taught, other in (pair, pair[::-1]):
            chosen = ceiling.oracle_cuts(taught.study, taught.truth, fps=taught.fps,
                                         tolerance_s=1.0)
            gains.append(scored(taught, chosen, 1.0)[0] - scored(other, chosen, 1.0)[0])
    return float(np.mean(gains)) if gains else None


def _corrupt(cuts: np.ndarray, mode: str, n_frames: int, fps: float, rng) -> np.ndarray:
    """An annotator's bad review: every other cut dropped (under), or as many extra cuts
    as there are, at random frames at least 2 s from any cut (over)."""
    if mode == "under":
        return cuts[::2]
    extra = []
    for _ in range(200):
        if len(extra) >= max(len(cuts), 3):
            break
        f = int(rng.integers(1, n_frames - 1))
        if all(abs(f - c) > 2 * fps for c in [*cuts, *extra]):
            extra.append(f)
    return np.unique(np.concatenate([cuts, np.asarray(extra, dtype=np.int64)]))


def poisoning(sets: list[LabelSet], out) -> dict:
    """Per by-subject set and mode: mean F1 change (poisoned - clean) on the held-out
    takes, and its mean absolute value."""
    print(f"\n## Poisoning: {POISONED} of up to {POISON_K} reviewed takes of other subjects "
          "under-cut (every other cut dropped) or over-cut (as many extra cuts) by one "
          f"annotator; F1 on the held-out take vs the clean model ({DRAWS} draws)", file=out)
    print(f"{'set':<12}{'reviewed':>9}{'mode':>7}{'clean F1':>10}{'poisoned':>10}"
          f"{'mean dF1':>10}{'mean |dF1|':>12}", file=out)
    result = {}
    for label in [s for s in sets if s.by_subject and s.items]:
        for mode in ("under", "over"):
            clean, bad, sizes = [], [], []
            for t, item in enumerate(label.items):
                pool = _pool(label, item)
                kk = min(POISON_K, len(pool))
                sizes.append(kk)
                for d in range(DRAWS):
                    rng = np.random.default_rng([t, d, 7])
                    chosen = [pool[i] for i in rng.choice(len(pool), kk, replace=False)]
                    hit = set(rng.choice(kk, POISONED, replace=False).tolist())
                    cuts = [_corrupt(c.cuts, mode, int(c.study["n_frames"]), c.fps, rng)
                            if j in hit else c.cuts for j, c in enumerate(chosen)]
                    for models, given in ((clean, None), (bad, cuts)):
                        model = fit(chosen, label.tolerance_s, given)
                        models.append(scored(item, adapt.cuts_in(item.study, model),
                                             label.tolerance_s)[0])
            delta = np.asarray(bad) - np.asarray(clean)
            result[(label.name, mode)] = (float(delta.mean()), float(np.abs(delta).mean()))
            print(f"{label.name:<12}{f'{min(sizes)}-{max(sizes)}':>9}{mode:>7}"
                  f"{np.mean(clean):>10.3f}{np.mean(bad):>10.3f}{delta.mean():>+10.3f}"
                  f"{np.abs(delta).mean():>12.3f}", file=out)
    return result


def targets(curves: dict, conv: float | None, poison: dict, out) -> None:
    print("\n## Targets (out of sample by subject where the set allows; the within-subject "
          "sets are listed for completeness, marked)", file=out)
    for name, (got, zs) in curves.items():
        row = got[TARGET_K][0]
        worse = [k for k in KS[1:] if got[k][0][0] < zs[0] - 1e-9]
        print(f"{name:<14} k={TARGET_K}: F1 {row[0]:.2f} (>= {TARGET_F1}: "
              f"{'met' if row[0] >= TARGET_F1 else 'NOT met'}), edits {row[1]:.2f} "
              f"(<= {TARGET_EDITS}: {'met' if row[1] <= TARGET_EDITS else 'NOT met'}); "
              f"never below zero-shot F1: "
              f"{'met' if not worse else 'NOT met at k=' + ','.join(map(str, worse))}",
              file=out)
    if conv is not None:
        print(f"convention-following: mean F1(taught) - F1(other) {conv:+.2f} (>= "
              f"+{TARGET_CONVENTION}: {'met' if conv >= TARGET_CONVENTION else 'NOT met'})",
              file=out)
    for (name, mode), (mean, absolute) in poison.items():
        print(f"poisoning {name} {mode}: mean dF1 {mean:+.3f} (the project's F1: "
              f"{'met' if abs(mean) < TARGET_POISON else 'NOT met'}), mean |dF1| "
              f"{absolute:.3f} (each next take: "
              f"{'met' if absolute < TARGET_POISON else 'NOT met'}; target < {TARGET_POISON})",
              file=out)


def main(root: Path | None = None, out=None) -> int:
    out = out or sys.stdout
    root = Path(root) if root else data.data_dir()
    if not root.is_dir():
        print(f"error: benchmark data folder not found: {root}", file=sys.stderr)
        return 2
    started = time.perf_counter()
    sets = load_sets(root, out)
    print(__doc__.split("\n\n")[1], file=out)
    curves = print_curves(sets, True, out)
    labels = learning_labels.print_curves(sets, KS, DRAWS, _pool, fit, scored, baseline, out)
    within = print_curves(sets, False, out)
    conv = convention(sets, out)
    conv_labels = learning_labels.convention(sets, fit, scored, out)
    costs = learning_labels.cost(out)
    print_ceiling(sets, {**curves, **within}, out)
    poison = poisoning(sets, out)
    print_tried(sets, curves, poison, out)
    targets({**curves, **{f"{k} (within)": v for k, v in within.items()}}, conv, poison, out)
    learning_labels.targets(labels, conv_labels, costs, out)
    print(f"\nlearning curve: {time.perf_counter() - started:.0f} s, load average "
          f"{' '.join(f'{x:.2f}' for x in os.getloadavg())}", file=out)
    return 0


@contextmanager
def labelled_as(labelling):
    """Every fit of this benchmark labels candidates with ``labelling`` inside the block
    (``LABELS``, its ``adapt.fit_cut_model(labels=...)``)."""
    global LABELS
    shipped, LABELS = LABELS, labelling
    try:
        yield
    finally:
        LABELS = shipped


def print_tried(sets, curves: dict, poison: dict, out) -> None:
    """For each labelling: the by-subject curve (F1, edits) beside the shipped one, the
    best count at k = TARGET_K, the poisoning case, and whether the shipping rule holds."""
    chosen = [s for s in sets if s.by_subject and s.items]
    print("\n## Tried, not shipped: other labellings of the candidates the learner learns "
          "from (benchmarks/quality/learning_tried.py); by subject, out of sample", file=out)
    print("F1 / review edits per true cut, shipped -> tried; best count at "
          f"k={TARGET_K} (oracle, as in the ceiling); poisoning mean dF1 under / "
          "over.", file=out)
    for name, labelling in learning_tried.LABELLINGS.items():
        worse = []
        with labelled_as(labelling):
            tried = {s.name: curve(s) for s in chosen}
            tried_poison = poisoning(sets, io.StringIO())
        for label in chosen:
            shipped, other = curves[label.name][0], tried[label.name]
            cells = []
            for k in KS[1:]:
                (f0, e0, _), (f1, e1, _) = shipped[k][0], other[k][0]
                cells.append(f"k={k} {f0:.2f}/{e0:.2f} -> {f1:.2f}/{e1:.2f}")
                if f1 < f0 - 1e-9 or e1 > e0 + 1e-9:
                    worse.append(f"{label.name} k={k}")
            moved = "; ".join(f"{tried_poison[(label.name, m)][0]:+.3f}"
                              for m in ("under", "over"))
            print(f"{name:<20}{label.name:<10}" + ", ".join(cells) +
                  f"; best count {shipped.get('best count', np.nan):.2f} -> "
                  f"{other.get('best count', np.nan):.2f}; poisoning {moved}", file=out)
        broken = [f"{n} {m}" for (n, m), (mean, _) in tried_poison.items()
                  if abs(mean) >= TARGET_POISON > abs(poison[(n, m)][0])]
        verdict = "shipping rule holds" if not worse and not broken else (
            "not shipped: " + ", ".join([*(f"worse at {w}" for w in worse),
                                         *(f"poisoning {b} no longer met" for b in broken)]))
        print(f"{name:<20}{verdict}", file=out)
