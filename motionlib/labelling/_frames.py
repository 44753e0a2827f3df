"""What is happening at every frame: a distance-weighted kNN over window descriptors.

A take is described at ``RATE_HZ`` by multi-scale window descriptors of the detector's own
per-frame features (``take_features``: body-frame pose for skeletons and known marker
sets, point coordinates for bare points, angles for channel takes): the pose averaged over
``SCALES_S`` centred windows and its spread over the middle one. A reviewed take gives one
reference point per sample, labelled with the label of the segment it lies in (or
``UNLABELLED``). The references are standardised, reduced by PCA to at most ``DIMS``
dimensions and sub-sampled to at most ``MAX_REFERENCES``; a take's posterior at a sample
is the distance-weighted vote of its ``NEIGHBOURS`` nearest references, smoothed with a
Dirichlet prior of ``PRIOR`` pseudo-votes spread as the references are.

The reduction is unsupervised on purpose: a metric learnt from the labels (Fisher's
discriminant directions were tried) would make the held-out check that gates the model
(``segmentation.similar.proposals``) see the held-out take's labels through the metric
unless it refitted the model per take, and refitted so, on pools of two or three reviewed
takes it did worse than a constant proposal (``docs/learner.md``).
"""

from __future__ import annotations

import numpy as np
from scipy.ndimage import uniform_filter1d
from scipy.spatial import cKDTree

from motionlib.points import segmenter_input
from motionlib.segmenters.default import Default
from motionlib.segmenters.default._features import block_mean, take_features

RATE_HZ = 5.0
SCALES_S = (0.4, 1.6, 4.0)
DIMS = 16
MAX_REFERENCES = 40_000
NEIGHBOURS = 12
PRIOR = 0.5
UNLABELLED = ""
# Neighbours may be up to (1 + APPROXIMATE) times farther than the exact ones: the
# tree's search then costs a fraction, and a vote of 12 barely changes.
APPROXIMATE = 0.5


def descriptors(take) -> tuple[np.ndarray, np.ndarray]:
    """(samples, descriptors): take frames of the samples (n,) and their window
    descriptors (n, 4 d) for a take whose detector features have d columns."""
    p = Default.validate_params({})
    x, first = take_features(segmenter_input(take, Default.name), velocity_s=p["velocity_s"])
    fps = float(take.fps)
    step = max(1, int(round(fps / RATE_HZ)))
    blocks = block_mean(np.nan_to_num(np.asarray(x, dtype=float)), step)
    if len(blocks) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((0, 4 * x.shape[1]))
    rate = fps / step
    parts = [uniform_filter1d(blocks, max(1, int(round(s * rate))), axis=0, mode="nearest")
             for s in SCALES_S]
    mid = max(1, int(round(SCALES_S[1] * rate)))
    square = uniform_filter1d(blocks ** 2, mid, axis=0, mode="nearest")
    spread = np.sqrt(np.maximum(square - parts[1] ** 2, 0.0))
    samples = first + step * np.arange(len(blocks)) + step // 2
    return samples.astype(np.int64), np.hstack([*parts, spread])


def frame_labels(segments, n_frames: int, names: list[str]) -> np.ndarray:
    """(n_frames,) index into ``names`` of each frame's label; ``segments`` are
    ``(start, end, label)`` with ``end`` exclusive, label None or "" for unlabelled."""
    out = np.full(n_frames, names.index(UNLABELLED), dtype=np.int64)
    for start, end, label in segments:
        if label:
            out[max(0, int(start)):max(0, min(n_frames, int(end)))] = names.index(label)
    return out


class Reduction:
    """Standardisation and PCA of reference descriptors (fitted once per model)."""

    def __init__(self, mean, scale, basis):
        self.mean, self.scale, self.basis = mean, scale, basis

    @classmethod
    def fit(cls, x: np.ndarray) -> Reduction:
        """Standardise ``x`` (n, d); then its ``DIMS`` principal directions."""
        mean = x.mean(axis=0)
        scale = x.std(axis=0)
        scale[scale < 1e-9] = 1.0
        z = (x - mean) / scale
        _, vectors = np.linalg.eigh(np.cov(z, rowvar=False).reshape(z.shape[1], -1))
        return cls(mean, scale, vectors[:, ::-1][:, :DIMS])

    def __call__(self, x: np.ndarray) -> np.ndarray:
        return ((x - self.mean) / self.scale) @ self.basis


def vote(tree: cKDTree, labels: np.ndarray, owners: np.ndarray, prior: np.ndarray,
         z: np.ndarray, exclude: int | None = None) -> np.ndarray:
    """(n, n_labels) posterior of each query row ``z``: distance-weighted votes of the
    nearest references (those of take ``exclude`` left out) plus the prior."""
    out = np.tile(prior * PRIOR, (len(z), 1))
    if len(z) == 0 or tree.n == 0:
        return out / out.sum(axis=1, keepdims=True)
    k = min(tree.n, NEIGHBOURS * (2 if exclude is not None else 1))
    dist, idx = tree.query(z, k=k, eps=APPROXIMATE)
    dist, idx = dist.reshape(len(z), k), idx.reshape(len(z), k)
    weight = 1.0 / (dist + 1e-3 + np.median(dist[:, :1]))
    if exclude is not None:
        weight = np.where(owners[idx] == exclude, 0.0, weight)
        # keep each query's NEIGHBOURS nearest remaining references
        rank = np.cumsum(weight > 0, axis=1)
        weight = np.where(rank <= NEIGHBOURS, weight, 0.0)
    rows = np.repeat(np.arange(len(z)), k)
    # each query's votes sum to NEIGHBOURS, against PRIOR pseudo-votes
    share = NEIGHBOURS * weight / np.maximum(weight.sum(axis=1, keepdims=True), 1e-12)
    np.add.at(out, (rows, labels[idx].ravel()), share.ravel())
    return out / out.sum(axis=1, keepdims=True)
