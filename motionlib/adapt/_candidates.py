"""Over-complete candidate cuts of one take and the evidence that describes each.

The zero-shot detector keeps a few strong novelty peaks. A studio's convention may keep
fewer, more (finer segments, weaker changes), or cut elsewhere; to learn which, every
take is first described by many more candidates than any convention keeps:

- the zero-shot cuts themselves, placed exactly as the detector places them;
- every other peak of the zero-shot novelty curve (any prominence down to
  ``LONG_PROMINENCE``);
- every peak of a short-window novelty curve (``SHORT_WINDOWS``), which sees activities
  shorter than the zero-shot windows;
- every turning point of the motion (a minimum of the 3 Hz pose speed) deeper than
  ``TURN_DEPTH`` times the take's median speed: where conventions that cut movement
  phases (reach, grasp, lift) cut, finer than any novelty window sees.

Peaks closer than ``MERGE_S`` to a candidate already listed add nothing (the earlier
source wins: zero-shot cut, then long, then short, then turning point). Each candidate carries a few evidence
features (``FEATURES``) and its frame at each placement step of the detector (the
anchors a model picks from). Nothing here depends on a studio's cuts, so a take's
candidates are computed once and serve every model and every refit.
"""

from __future__ import annotations

import numpy as np
from scipy.signal import find_peaks

from motionlib.segmenters import default
from motionlib.segmenters.default import PLACEMENTS

# The short novelty windows (s): activities of a second or two.
SHORT_WINDOWS = (1.0, 2.0)
# The weakest peaks listed (MMD² prominence) on each curve, and the closest two
# candidates may lie (s).
LONG_PROMINENCE = 0.005
SHORT_PROMINENCE = 0.01
MERGE_S = 0.3
TURN_DEPTH = 0.1
# Evidence features, in the order of a study's ``features`` columns. MMD² values are
# logged (their scale is multiplicative) with a floor well below the weakest peak listed.
FEATURES = ("zero_shot", "long_height", "long_prominence", "short_height",
            "short_prominence", "support", "speed", "near_zero_shot", "turn_depth")
FLOOR = 0.003


def study_take(take, p: dict) -> dict[str, np.ndarray] | None:
    """The arrays of :func:`candidates_of` alone (what is stored of an example)."""
    found = candidates_of(take, p)
    return None if found is None else found[0]


def candidates_of(take, p: dict):
    """Candidates of ``take`` (a segmenter input) under the validated default settings
    ``p``; None when the take is too short to analyse.

    Returns
    -------
    A dict of arrays: ``features`` (n, len(FEATURES)); ``zero_shot`` (n,) bool;
    ``stages`` (n, len(PLACEMENTS)) int take frames of each candidate at each placement
    step; ``fps`` and ``n_frames`` (0-d). Candidates are in frame order of their
    ``split`` step.
    """
    analysis = default.analyse(take, p)
    if analysis is None:
        return None
    found = default.peaks(analysis, p)
    placed = default.place(analysis, found, p)
    short = analysis.with_windows(SHORT_WINDOWS)[0]
    rate = analysis.rate
    merge = max(1, int(round(MERGE_S * rate)))
    long_peaks, long_prom = _all_peaks(analysis.novelty, merge, LONG_PROMINENCE)
    short_peaks, short_prom = _all_peaks(short.novelty, merge, SHORT_PROMINENCE)
    turns = _turns(analysis, merge)
    samples = np.asarray(found.samples, dtype=np.int64)
    zero = len(samples)
    for extra in (long_peaks, short_peaks, turns):
        samples = np.concatenate([samples, _apart(extra, samples, merge)])
    stages = np.empty((len(samples), len(PLACEMENTS)), dtype=np.int64)
    for j, name in enumerate(PLACEMENTS):
        stages[:zero, j] = placed.stages[name]
    if len(samples) > zero:
        # The extra candidates are placed among each other and the zero-shot cuts, each
        # step bounded half-way to its neighbours as the detector bounds its own cuts.
        order = np.argsort(samples, kind="stable")
        extra_stages = default.place_samples(analysis, samples[order], p, only=order >= zero)
        back = np.empty_like(order)
        back[order] = np.arange(len(order))
        for j, name in enumerate(PLACEMENTS):
            stages[zero:, j] = extra_stages[name][back][zero:]
    stages += analysis.first
    features = _features(analysis, short, samples, zero, (long_peaks, long_prom),
                         (short_peaks, short_prom))
    order = np.argsort(stages[:, 0], kind="stable")
    zero_shot = np.arange(len(samples)) < zero
    arrays = {"features": features[order], "zero_shot": zero_shot[order],
              "stages": stages[order], "fps": np.asarray(analysis.fps),
              "n_frames": np.asarray(len(analysis.x) + analysis.first)}
    return arrays, analysis, placed.speed


def _turns(analysis, merge: int) -> np.ndarray:
    """Novelty samples of the turning points deeper than TURN_DEPTH x the median speed."""
    fine = analysis.speeds[1]
    typical = max(float(np.median(fine)), 1e-9)
    frames, _ = find_peaks(-fine, prominence=TURN_DEPTH * typical,
                           distance=max(1, merge * analysis.step))
    return np.unique(frames // analysis.step)


def _depth(fine: np.ndarray, frames: np.ndarray, fps: float) -> np.ndarray:
    """How far the pose speed dips at each frame: the highest speed within 0.5 s less the
    lowest within 0.15 s, over the take's median speed."""
    _n, wide, narrow = len(fine), int(round(0.5 * fps)), max(1, int(round(0.15 * fps)))
    typical = max(float(np.median(fine)), 1e-9)
    return np.asarray([(fine[max(0, f - wide):f + wide + 1].max() -
                        fine[max(0, f - narrow):f + narrow + 1].min()) / typical
                       for f in frames.tolist()])


def _apart(new: np.ndarray, old: np.ndarray, merge: int) -> np.ndarray:
    """The samples of ``new`` at least ``merge`` from every sample of ``old`` and from
    the ones of ``new`` kept before them (in order)."""
    kept: list[int] = []
    ordered = np.sort(old)
    for k in np.asarray(new, dtype=np.int64).tolist():
        i = int(np.searchsorted(ordered, k))
        near_old = (i < len(ordered) and ordered[i] - k < merge) or \
            (i > 0 and k - ordered[i - 1] < merge)
        if not near_old and all(abs(k - j) >= merge for j in kept[-2:]):
            kept.append(k)
    return np.asarray(kept, dtype=np.int64)


def _all_peaks(curve: np.ndarray, distance: int, prominence: float):
    """Peaks of ``curve`` (samples) at least ``distance`` apart, and their prominences."""
    padded = np.concatenate([[0.0], curve, [0.0]])
    peaks, props = find_peaks(padded, distance=distance, prominence=prominence)
    return peaks - 1, props["prominences"]


def _near(samples: np.ndarray, peaks: np.ndarray, values: np.ndarray, reach: int) -> np.ndarray:
    """For each sample, the value of the nearest peak within ``reach`` samples (0 if none)."""
    out = np.zeros(len(samples))
    if len(peaks) == 0:
        return out
    j = np.clip(np.searchsorted(peaks, samples), 1, len(peaks)) - 1
    j = np.where((j + 1 < len(peaks)) & (np.abs(peaks[np.minimum(j + 1, len(peaks) - 1)]
                                                - samples) < np.abs(peaks[j] - samples)),
                 j + 1, j)
    near = np.abs(peaks[j] - samples) <= reach
    out[near] = values[j[near]]
    return out


def _height(curve: np.ndarray, samples: np.ndarray, reach: int) -> np.ndarray:
    """The curve's highest value within ``reach`` samples of each sample."""
    n = len(curve)
    return np.asarray([curve[max(0, k - reach):min(n, k + reach + 1)].max()
                       for k in samples.tolist()]) if n else np.zeros(len(samples))


def _features(analysis, short, samples, zero, long, short_peaks) -> np.ndarray:
    """(n, len(FEATURES)) evidence of each candidate (see FEATURES)."""
    reach = max(1, int(round(MERGE_S * analysis.rate)))
    log = lambda v: np.log(np.maximum(v, 0.0) + FLOOR)  # noqa: E731
    support = default.peak_support(analysis, samples)
    support = np.where(np.isfinite(support), support, 2.0)
    speed = analysis.speeds[0]
    frames = np.clip(analysis.peak_frames(samples), 0, len(speed) - 1)
    typical = max(float(np.median(speed)), 1e-9)
    zs = np.arange(len(samples)) < zero
    zero_frames = samples[zs]
    near = np.full(len(samples), 10.0)
    if len(zero_frames):
        gap = np.abs(samples[:, None] - zero_frames[None, :]) / analysis.rate
        gap[zs] = np.inf  # a zero-shot cut's distance to the others is not the point
        near = np.minimum(gap.min(axis=1), 10.0)
    near[zs] = 10.0
    return np.stack([
        zs.astype(float),
        log(_height(analysis.novelty, samples, reach)),
        log(_near(samples, *long, reach)),
        log(_height(short.novelty, samples, reach)),
        log(_near(samples, *short_peaks, reach)),
        np.log(np.minimum(support, 20.0) + 0.05),
        np.log(speed[frames] / typical + 0.05),
        np.log(near + 0.1),
        np.log(_depth(analysis.speeds[1], frames, analysis.fps) + 0.05),
    ], axis=1)
