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

Why nearest neighbours for 1-50 reviewed takes (``docs/learner.md``): they have no
parameter to fit, so one reviewed take already gives a usable posterior and fifty make it
finer without a training run; a new label is known as soon as one take carries it; a
renamed, retired or merged label is a relabelling of the references, not a retrain; and
their cost is a tree query per sample (5 Hz), a few seconds for a 60-minute take.

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
            "labels": pack(self.labels, "<i4"), "owners": pack(self.owners, "<i4")})

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
                       {k: tuple(v) for k, v in d["lengths"].items()}, int(d["n_takes"]))
        except (KeyError, TypeError, ValueError) as exc:
            raise InputError(f"not a stored frame model: {exc}") from None


def fit_frame_model(examples: Sequence[FrameExample]) -> FrameModel | None:
    """Learn a :class:`FrameModel` from reviewed takes; None when there is none or no
    take carries a label (nothing to tell apart)."""
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
    return FrameModel(names, reduction, reduction(x), y, own, _lengths(examples),
                      len(examples))


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


def propose(model: FrameModel, post: np.ndarray, cuts) -> list[tuple[str | None, float]]:
    """For each segment between ``cuts`` (take frames), its most likely label and that
    label's probability (the mean over its frames); None, with the probability of
    "unlabelled", when that is more likely than not."""
    bounds = np.concatenate([[0], np.sort(np.asarray(cuts, dtype=np.int64)), [len(post)]])
    out = []
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        mean = post[lo:max(hi, lo + 1)].mean(axis=0)
        best = 0 if mean[0] > 0.5 else 1 + int(np.argmax(mean[1:]))
        out.append((model.names[best] or None, round(float(mean[best]), 4)))
    return out


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
    return FrameModel(names, model.reduction, model.references, index[model.labels],
                      model.owners, lengths, model.n_takes)


def decode(model: FrameModel, post: np.ndarray, fps: float) -> np.ndarray:
    """(n_frames,) the most likely label index at every frame as a sequence of stretches:
    Viterbi over the posterior sampled at the frame model's rate, a label change costing
    the log of the project's usual segment length (in samples), so that a stretch ends
    where the posterior changes for longer than a moment, not at every flicker."""
    n = len(post)
    step = max(1, int(round(fps / _frames.RATE_HZ)))
    emit = np.log(np.maximum(post[::step], 1e-6))
    usual = np.exp(np.mean([m for m, _ in model.lengths.values()])) if model.lengths else 5.0
    stay = max(2.0, usual * fps / step)
    switch = np.log(1.0 / stay / max(1, post.shape[1] - 1))
    keep = np.log(1.0 - 1.0 / stay)
    score = emit[0].copy()
    back = np.zeros(emit.shape, dtype=np.int64)
    for t in range(1, len(emit)):
        best = int(np.argmax(score))
        moved = score[best] + switch
        back[t] = np.where(score + keep >= moved, np.arange(len(score)), best)
        score = np.maximum(score + keep, moved) + emit[t]
    path = np.empty(len(emit), dtype=np.int64)
    path[-1] = int(np.argmax(score))
    for t in range(len(emit) - 1, 0, -1):
        path[t - 1] = back[t, path[t]]
    return np.repeat(path, step)[:n] if len(path) * step >= n else \
        np.concatenate([np.repeat(path, step), np.full(n - len(path) * step, path[-1])])
