"""A project's model of what is happening at every frame, learnt from its reviewed takes.

:func:`fit_frame_model` learns, from reviewed takes and their labelled segments, a
:class:`FrameModel`: for any take, :func:`posterior` gives at every frame a probability
over the project's labels plus ``UNLABELLED`` (the stretches a reviewer left without a
label). It is a distance-weighted nearest-neighbour vote over multi-scale window
descriptors of the detector's own per-frame features (``_frames``), so it works on
skeleton, point and channel takes alike. From it:

- :func:`propose` gives every segment of a cut take its most likely label and that
  label's probability (segments arrive labelled);
- ``motionlib.labelling.evidence`` describes every candidate cut by what the posterior
  says across it, the evidence the label-aware cut scorer adds to the learner's.

What happens at one frame is read better from the frames around it: :func:`decode` turns
the posterior into a sequence of labelled stretches with a hidden Markov model whose
label-to-label transitions, usual lengths and first label are counted from the reviewed
takes (a studio whose takes follow a script teaches the script), and whose trust in the
per-frame posterior (``FrameModel.sharpness``) is chosen by :func:`fit_frame_model` on
the reviewed takes themselves, each fold of them seen through a model fitted without it.

Why nearest neighbours for 1-50 reviewed takes (``docs/learner.md``): they have no
parameter to fit, so one reviewed take already gives a usable posterior
and fifty make it finer without a training run; a new label is known as soon as one take
carries it; a renamed, retired or merged label is a relabelling of the references (and of
the transition counts), not a retrain; and their cost is a tree query per sample (5 Hz),
a few seconds for a 60-minute take. The metric is unsupervised (``_frames``: PCA of the
standardised descriptors), so the held-out check that gates the model is not optimistic.

Pure numpy/scipy, no Django.
"""

from __future__ import annotations

import base64
import json
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from scipy.spatial import cKDTree

from motionlib.errors import InputError
from motionlib.labelling import _frames
from motionlib.labelling._frames import UNLABELLED, descriptors, frame_labels

__all__ = ["UNLABELLED", "FrameExample", "FrameModel", "fit_frame_model",
           "frame_example", "posterior", "propose", "relabelled"]

FORMAT = 1
# Pseudo-counts added to every label-to-label transition and first label (add-half, the
# customary Jeffreys smoothing: an order the reviewed takes never showed stays possible).
ALPHA = 0.5
# The trusts in the per-frame posterior (the power its likelihood ratio is raised to)
# that fitting chooses among, on the reviewed takes' own folds; and at most how many folds.
SHARPNESS = (1.0, 0.3, 0.1, 0.03)
FOLDS = 5


@dataclass
class FrameExample:
    """A reviewed take as the frame model reads it: its descriptors (``_frames``), length
    and labelled segments ``(start, end, label)`` (take frames, end exclusive, label ""
    or None when the reviewer left it unlabelled)."""

    samples: np.ndarray
    descriptors: np.ndarray
    n_frames: int
    fps: float
    segments: list = field(default_factory=list)


def frame_example(take, segments) -> FrameExample:
    """A reviewed take and its segments as a :class:`FrameExample` (reads the take once)."""
    samples, x = descriptors(take)
    return FrameExample(samples, x, int(take.n_frames), float(take.fps), list(segments))


@dataclass
class FrameModel:
    """Reference points of a project's reviewed takes, reduced; see the module."""

    names: list[str]
    reduction: _frames.Reduction
    references: np.ndarray  # (m, dims) reduced descriptors
    labels: np.ndarray  # (m,) index into names
    owners: np.ndarray  # (m,) which example take
    lengths: dict  # label -> (mean, sd) of log segment length (s)
    n_takes: int
    _tree: cKDTree | None = None
    # (n_labels, n_labels) label-to-label changes and (n_labels,) first labels counted on
    # the reviewed takes; None in a model stored before they were (uniform then)
    transitions: np.ndarray | None = None
    starts: np.ndarray | None = None
    sharpness: float = 1.0

    @property
    def tree(self) -> cKDTree:
        if self._tree is None:
            self._tree = cKDTree(self.references)
        return self._tree

    @property
    def prior(self) -> np.ndarray:
        counts = np.bincount(self.labels, minlength=len(self.names)).astype(float)
        return (counts + 1.0) / (counts.sum() + len(counts))

    def to_json(self) -> str:
        """The model as JSON text (references stored as float32 base64)."""
        def pack(a, dtype):
            return base64.b64encode(np.ascontiguousarray(a, dtype=dtype).tobytes()).decode()
        r = self.reduction
        return json.dumps({
            "format": FORMAT, "names": self.names, "n_takes": self.n_takes,
            "lengths": self.lengths, "dims": int(self.references.shape[1]),
            "in": int(r.mean.shape[0]),
            "mean": pack(r.mean, "<f8"), "scale": pack(r.scale, "<f8"),
            "basis": pack(r.basis, "<f8"), "references": pack(self.references, "<f4"),
            "labels": pack(self.labels, "<i4"), "owners": pack(self.owners, "<i4"),
            "transitions": None if self.transitions is None else self.transitions.tolist(),
            "starts": None if self.starts is None else self.starts.tolist(),
            "sharpness": self.sharpness})

    @classmethod
    def from_json(cls, text: str) -> FrameModel:
        """Read :meth:`to_json`'s text back; InputError naming what is wrong."""
        try:
            d = json.loads(text)
            if d.get("format") != FORMAT:
                raise InputError(f"frame model format {d.get('format')!r} is not {FORMAT}")
            dims, n_in = int(d["dims"]), int(d["in"])

            def unpack(key, dtype):
                return np.frombuffer(base64.b64decode(d[key]), dtype=dtype).copy()
            reduction = _frames.Reduction(unpack("mean", "<f8"), unpack("scale", "<f8"),
                                          unpack("basis", "<f8").reshape(n_in, dims))
            return cls(list(d["names"]), reduction,
                       unpack("references", "<f4").astype(float).reshape(-1, dims),
                       unpack("labels", "<i4").astype(np.int64),
                       unpack("owners", "<i4").astype(np.int64),
                       {k: tuple(v) for k, v in d["lengths"].items()}, int(d["n_takes"]),
                       transitions=_array(d.get("transitions"), (len(d["names"]),) * 2),
                       starts=_array(d.get("starts"), (len(d["names"]),)),
                       sharpness=float(d.get("sharpness", 1.0)))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"not a stored frame model: {exc}") from None


def _array(value, shape) -> np.ndarray | None:
    if value is None:
        return None
    out = np.asarray(value, dtype=float)
    if out.shape != shape:
        raise InputError(f"counts of shape {out.shape}, expected {shape}")
    return out


def fit_frame_model(examples: Sequence[FrameExample], *, groups=None,
                    tolerance_s: float = 1.0) -> FrameModel | None:
    """Learn a :class:`FrameModel` from reviewed takes; None when there is none or no
    take carries a label (nothing to tell apart).

    ``groups`` (one key per take, e.g. its performer; by default each take its own) make
    the folds, at most ``FOLDS``, on which the model's ``sharpness`` is chosen: each fold's
    takes decoded by a model fitted on the others, the sharpness whose decoded stretches
    best match the reviewed ones wins: the share of samples whose decoded label is the
    reviewed one, less the |log| ratio of decoded stretches to reviewed segments. Not the
    boundary F1: a reviewed cut is a point where a studio may accept a whole pause, and
    a decoded change at the pause's end would count as a miss. With a single fold the
    first of ``SHARPNESS`` is kept. ``tolerance_s`` is accepted for the callers that pass
    their set's tolerance; the choice does not depend on it."""
    model = _fit(examples)
    if model is None:
        return None
    folds = _folds(examples, groups)
    if len(set(folds)) > 1:
        model.sharpness = _chosen_sharpness(examples, folds, tolerance_s)
    return model


def _folds(examples, groups) -> list[int]:
    """Fold of each example: its group's rank in order of appearance, modulo FOLDS."""
    keys = list(range(len(examples))) if groups is None else list(groups)
    seen: dict = {}
    return [seen.setdefault(k, len(seen)) % FOLDS for k in keys]


def out_of_fold(examples: Sequence[FrameExample], folds) -> list:
    """For each example, (model, sample posterior) from a frame model fitted on the other
    folds' takes (None where those carry no label)."""
    out: list = [None] * len(examples)
    for f in sorted(set(folds)):
        model = _fit([e for e, g in zip(examples, folds, strict=True) if g != f])
        for i, (e, g) in enumerate(zip(examples, folds, strict=True)):
            if g == f and model is not None:
                out[i] = (model, _frames.vote(model.tree, model.labels, model.owners,
                                              model.prior, model.reduction(e.descriptors)))
    return out


def _chosen_sharpness(examples, folds, tolerance_s: float) -> float:
    seen = out_of_fold(examples, folds)
    scores = np.zeros(len(SHARPNESS))
    for e, got in zip(examples, seen, strict=True):
        if got is None or len(e.samples) < 2:
            continue
        model, at = got
        # a label the other folds never saw cannot be matched: -1
        known = [(a, b, lab if (lab or UNLABELLED) in model.names else "?")
                 for a, b, lab in e.segments]
        truth = frame_labels(known, e.n_frames, [*model.names, "?"])[
            np.clip(e.samples, 0, e.n_frames - 1)]
        for j, sharp in enumerate(SHARPNESS):
            path = _viterbi(model, at, e.fps / _step(e.fps), sharp)
            scores[j] += np.mean(path == truth) - _count_misfit(e, path)
    return float(SHARPNESS[int(np.argmax(scores))])


def _count_misfit(e: FrameExample, path: np.ndarray) -> float:
    """|log| of the ratio of decoded stretches to reviewed segments (+1 each)."""
    found = int(np.count_nonzero(np.diff(path)))
    true = sum(1 for s, _, _ in e.segments if 0 < s < e.n_frames)
    return abs(float(np.log((found + 1) / (true + 1))))


def _step(fps: float) -> int:
    return max(1, int(round(fps / _frames.RATE_HZ)))


def _fit(examples: Sequence[FrameExample]) -> FrameModel | None:
    names = [UNLABELLED] + sorted({str(lab) for e in examples for _, _, lab in e.segments
                                   if lab})
    if not examples or len(names) == 1:
        return None
    xs, ys, owners = [], [], []
    for i, e in enumerate(examples):
        keep = (e.samples >= 0) & (e.samples < e.n_frames)
        xs.append(e.descriptors[keep])
        ys.append(frame_labels(e.segments, e.n_frames, names)[e.samples[keep]])
        owners.append(np.full(int(keep.sum()), i))
    x, y, own = np.vstack(xs), np.concatenate(ys), np.concatenate(owners)
    if len(x) > _frames.MAX_REFERENCES:  # an even stride keeps every take's share
        pick = np.linspace(0, len(x) - 1, _frames.MAX_REFERENCES).astype(np.int64)
        x, y, own = x[pick], y[pick], own[pick]
    reduction = _frames.Reduction.fit(x)
    changes, starts = _counts(examples, names)
    return FrameModel(names, reduction, reduction(x), y, own, _lengths(examples),
                      len(examples), transitions=changes, starts=starts)


def _counts(examples, names) -> tuple[np.ndarray, np.ndarray]:
    """How often each label follows another (consecutive segments of different labels)
    and how often each opens a take, over the reviewed takes."""
    changes = np.zeros((len(names), len(names)))
    starts = np.zeros(len(names))
    for e in examples:
        seq = [names.index(lab or UNLABELLED) for _, _, lab in sorted(e.segments)]
        if seq:
            starts[seq[0]] += 1
        for a, b in zip(seq[:-1], seq[1:], strict=True):
            if a != b:
                changes[a, b] += 1
    return changes, starts


def _lengths(examples) -> dict:
    """label -> (mean, sd) of the log length (s) of its segments; sd floored."""
    seen: dict[str, list[float]] = {}
    for e in examples:
        for start, end, label in e.segments:
            if end > start:
                seen.setdefault(label or UNLABELLED, []).append(np.log((end - start) / e.fps))
    return {k: (float(np.mean(v)), float(max(np.std(v), 0.3))) for k, v in seen.items()}


def posterior(model: FrameModel, example, *, exclude: int | None = None) -> np.ndarray:
    """(n_frames, len(model.names)) probability of each label at every frame of a take
    (a :class:`FrameExample`, or a take), each frame taking its nearest sample's;
    ``exclude`` leaves one example take's references out (its out-of-sample view)."""
    if not isinstance(example, FrameExample):
        example = frame_example(example, [])
    z = model.reduction(example.descriptors)
    at = _frames.vote(model.tree, model.labels, model.owners, model.prior, z, exclude)
    if len(at) == 0:
        return np.tile(model.prior, (example.n_frames, 1))
    frames = np.arange(example.n_frames)
    nearest = np.clip(np.searchsorted(example.samples, frames), 0, len(at) - 1)
    return at[nearest]


def propose(model: FrameModel, post: np.ndarray, cuts, *,
            fps: float | None = None) -> list[tuple[str | None, float]]:
    """For each segment between ``cuts`` (take frames), its most likely label and that
    label's probability (the mean over its frames); None, with the probability of
    "unlabelled", when that is more likely than not. Given the take's ``fps``, the labels
    of all segments are decoded together (:func:`_segment_path`), so the order of labels
    the reviewed takes showed speaks too."""
    bounds = np.concatenate([[0], np.sort(np.asarray(cuts, dtype=np.int64)), [len(post)]])
    spans = list(zip(bounds[:-1], np.maximum(bounds[1:], bounds[:-1] + 1), strict=True))
    means = np.asarray([post[lo:hi].mean(axis=0) for lo, hi in spans]).reshape(-1, post.shape[1])
    if fps and len(post):
        best = _segment_path(model, post, spans, fps)
    else:
        best = [0 if m[0] > 0.5 else 1 + int(np.argmax(m[1:])) for m in means]
    return [(model.names[b] or None, round(float(m[b]), 4)) for b, m in zip(best, means,
                                                                           strict=True)]


def _segment_path(model: FrameModel, post: np.ndarray, spans, fps: float) -> np.ndarray:
    """The most likely label of every segment, jointly: each segment's evidence is the
    sum over its samples of the sharpened likelihood ratio (as :func:`decode`'s), and
    consecutive segments change label as the reviewed takes did, or keep it (a cut
    inside an action) with even odds."""
    step = _step(fps)
    ratio = model.sharpness * (np.log(np.maximum(post, 1e-6)) - np.log(model.prior))
    emit = np.asarray([ratio[lo:hi].sum(axis=0) / step for lo, hi in spans])
    log_a, log_start = _transitions(model, 1.0)
    change = log_a.copy()
    np.fill_diagonal(change, -np.inf)
    change = change - np.logaddexp.reduce(change, axis=1, keepdims=True) + np.log(0.5)
    np.fill_diagonal(change, np.log(0.5))
    return _best_path(change, log_start, emit)


def _best_path(log_a: np.ndarray, log_start: np.ndarray, emit: np.ndarray) -> np.ndarray:
    n_labels = emit.shape[1]
    score = log_start + emit[0]
    back = np.zeros(emit.shape, dtype=np.int32)
    for t in range(1, len(emit)):
        moved = score[:, None] + log_a
        back[t] = moved.argmax(axis=0)
        score = moved[back[t], np.arange(n_labels)] + emit[t]
    path = np.empty(len(emit), dtype=np.int64)
    path[-1] = int(np.argmax(score))
    for t in range(len(emit) - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return path


def relabelled(model: FrameModel, mapping: dict[str, str | None]) -> FrameModel:
    """The model after a taxonomy change: ``mapping`` renames (old -> new), merges (two
    olds -> one new) or retires (old -> None: its references become unlabelled) labels;
    labels not named keep theirs. No retraining: the references keep their descriptors."""
    new_of = [mapping.get(n, n) if n else UNLABELLED for n in model.names]
    new_of = [n or UNLABELLED for n in new_of]
    names = [UNLABELLED] + sorted({n for n in new_of if n})
    index = np.asarray([names.index(n) for n in new_of], dtype=np.int64)
    lengths: dict = {}
    for old, (m, s) in model.lengths.items():
        lengths.setdefault(mapping.get(old, old) or UNLABELLED, (m, s))
    changes = starts = None
    if model.transitions is not None and model.starts is not None:
        changes = np.zeros((len(names), len(names)))
        np.add.at(changes, (index[:, None], index[None, :]), model.transitions)
        np.fill_diagonal(changes, 0.0)  # two labels merged: a change between them is none
        starts = np.bincount(index, weights=model.starts, minlength=len(names))
    return FrameModel(names, model.reduction, model.references, index[model.labels],
                      model.owners, lengths, model.n_takes, transitions=changes,
                      starts=starts, sharpness=model.sharpness)


def decode(model: FrameModel, post: np.ndarray, fps: float) -> np.ndarray:
    """(n_frames,) the most likely label index at every frame as a sequence of stretches:
    Viterbi over the posterior sampled at the frame model's rate, under a hidden Markov
    model whose label changes follow the reviewed takes' counts (``transitions``,
    ``starts``, smoothed by ``ALPHA``) and whose stay in a label lasts its usual length,
    the posterior's likelihood ratio raised to the model's ``sharpness``."""
    n = len(post)
    step = _step(fps)
    path = _viterbi(model, post[::step], fps / step, model.sharpness)
    return np.repeat(path, step)[:n] if len(path) * step >= n else \
        np.concatenate([np.repeat(path, step), np.full(n - len(path) * step, path[-1])])


def _viterbi(model: FrameModel, at: np.ndarray, rate: float, sharpness: float) -> np.ndarray:
    """(m,) the most likely label path of sample posteriors ``at`` (m, n_labels)."""
    emit = sharpness * (np.log(np.maximum(at, 1e-6)) - np.log(model.prior))
    log_a, log_start = _transitions(model, rate)
    return _best_path(log_a, log_start, emit)


def _transitions(model: FrameModel, rate: float) -> tuple[np.ndarray, np.ndarray]:
    """(log transition matrix, log first-label probabilities) at ``rate`` samples/s."""
    k = len(model.names)
    overall = np.mean([m for m, _ in model.lengths.values()]) if model.lengths else np.log(5.0)
    usual = np.asarray([model.lengths.get(n, (overall, 1.0))[0] for n in model.names])
    stay = 1.0 - 1.0 / np.maximum(2.0, np.exp(usual) * rate)
    changes = np.zeros((k, k)) if model.transitions is None else model.transitions
    starts = np.zeros(k) if model.starts is None else model.starts
    off = changes + ALPHA
    np.fill_diagonal(off, 0.0)
    off = off / np.maximum(off.sum(axis=1, keepdims=True), 1e-12) * (1.0 - stay)[:, None]
    off[np.arange(k), np.arange(k)] = stay
    first = (starts + ALPHA) / (starts + ALPHA).sum()
    return np.log(np.maximum(off, 1e-12)), np.log(first)
