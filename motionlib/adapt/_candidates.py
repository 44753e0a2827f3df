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
source wins: zero-shot cut, then long, then short, then turning point). Each candidate
carries a few evidence features (``_evidence``) and its frame at each placement step of
the detector (the anchors a model picks from). Nothing here depends on a studio's cuts,
so a take's candidates are computed once and serve every model and every refit. Only
the detector's public steps are read (``segmenters.default``).
"""

from __future__ import annotations

import numpy as np
from scipy.signal import find_peaks

from motionlib.adapt._evidence import evidence
from motionlib.points import segmenter_input
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


def study_take(take, p: dict) -> dict[str, np.ndarray] | None:
    """The arrays of :func:`candidates_of` alone (what is stored of an example) for a take
    as read (bare points become their coordinates, as the detector reads them)."""
    found = candidates_of(segmenter_input(take, default.Default.name), p)
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
    features = evidence(analysis, samples, zero, merge, (long_peaks, long_prom),
                        (short, short_peaks, short_prom))
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


