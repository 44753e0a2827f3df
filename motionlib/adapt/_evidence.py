"""The evidence that describes each candidate cut: the columns of a study's ``features``,
the logistic scorer's inputs (``_model.design``).

Each column is one row of :data:`EVIDENCE` (its name and its typical value, which the
scorer centres it on) and one entry of :func:`evidence`. The scorer's prior gives every
column but ``zero_shot`` a weight of 0, so a column added here leaves the zero-shot
model (no example) exactly the zero-shot detector; the examples then weigh it as far as
they agree. Evidence that depends on the other reviewed takes (a model fitted on them)
rather than on the take alone is computed at fitting time, not kept in the study.
"""

from __future__ import annotations

import numpy as np

from motionlib.segmenters import default

# Evidence features, in the order of a study's ``features`` columns, each with its fixed
# centre (a typical value), so that the intercept means "a typical candidate" and the
# prior on it is not dodged through a feature's offset. Every feature but ``zero_shot``
# is a logarithm: MMD² values with a floor (FLOOR) well below the weakest peak listed,
# the others with a small offset (``evidence``), since their scales are multiplicative.
EVIDENCE = (
    ("zero_shot", 0.0),  # 1 for the zero-shot detector's own cuts
    ("long_height", -2.3),  # the zero-shot novelty curve's height near the candidate
    ("long_prominence", -2.3),  # the prominence of its nearest peak on that curve
    ("short_height", -1.0),  # the same on the short-window curve
    ("short_prominence", -2.3),
    ("support", 0.0),  # how much of each side the other lacks (``default.peak_support``)
    ("speed", 0.0),  # the 1 Hz pose speed there, over the take's median
    ("near_zero_shot", 1.0),  # how far (s) the nearest zero-shot cut lies, at most 10
    ("turn_depth", 0.0),  # how far the 3 Hz pose speed dips there
)
FEATURES = tuple(name for name, _ in EVIDENCE)
CENTRES = np.array([centre for _, centre in EVIDENCE])
FLOOR = 0.003


def evidence(analysis, samples: np.ndarray, zero: int, reach: int, long: tuple,
             short: tuple) -> np.ndarray:
    """(n, len(FEATURES)) the evidence of each candidate (see EVIDENCE).

    ``samples`` (n,) are the candidates' novelty samples of ``analysis``, the ``zero``
    zero-shot cuts first; ``reach`` (samples) how near a curve's peak or height counts;
    ``long`` the zero-shot curve's (peaks, prominences); ``short`` (analysis at the short
    windows, peaks, prominences).
    """
    log = lambda v: np.log(np.maximum(v, 0.0) + FLOOR)  # noqa: E731
    short_analysis, *short_peaks = short
    support = default.peak_support(analysis, samples)
    support = np.where(np.isfinite(support), support, 2.0)
    speed = analysis.speeds[0]
    frames = np.clip(analysis.peak_frames(samples), 0, len(speed) - 1)
    typical = max(float(np.median(speed)), 1e-9)
    zs = np.arange(len(samples)) < zero
    columns = {
        "zero_shot": zs.astype(float),
        "long_height": log(_height(analysis.novelty, samples, reach)),
        "long_prominence": log(_near(samples, *long, reach)),
        "short_height": log(_height(short_analysis.novelty, samples, reach)),
        "short_prominence": log(_near(samples, *short_peaks, reach)),
        "support": np.log(np.minimum(support, 20.0) + 0.05),
        "speed": np.log(speed[frames] / typical + 0.05),
        "near_zero_shot": np.log(_near_zero_shot(samples, zs, analysis.rate) + 0.1),
        "turn_depth": np.log(_depth(analysis.speeds[1], frames, analysis.fps) + 0.05),
    }
    return np.stack([columns[name] for name in FEATURES], axis=1)


def _near_zero_shot(samples: np.ndarray, zs: np.ndarray, rate: float) -> np.ndarray:
    """(n,) how far (s) each candidate lies from the nearest zero-shot cut, at most 10;
    10 for the zero-shot cuts themselves (their distance to the others is not the point)."""
    zero_frames = samples[zs]
    near = np.full(len(samples), 10.0)
    if len(zero_frames):
        gap = np.abs(samples[:, None] - zero_frames[None, :]) / rate
        gap[zs] = np.inf
        near = np.minimum(gap.min(axis=1), 10.0)
    near[zs] = 10.0
    return near


def _depth(fine: np.ndarray, frames: np.ndarray, fps: float) -> np.ndarray:
    """How far the pose speed dips at each frame: the highest speed within 0.5 s less the
    lowest within 0.15 s, over the take's median speed."""
    _n, wide, narrow = len(fine), int(round(0.5 * fps)), max(1, int(round(0.15 * fps)))
    typical = max(float(np.median(fine)), 1e-9)
    return np.asarray([(fine[max(0, f - wide):f + wide + 1].max() -
                        fine[max(0, f - narrow):f + narrow + 1].min()) / typical
                       for f in frames.tolist()])


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
