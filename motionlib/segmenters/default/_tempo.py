"""The ``tempo`` option: time settings scaled by the take's own movement cycle."""

from __future__ import annotations

import numpy as np

from motionlib.segmenters.default._features import block_mean

# Tempo: the movement cycle (s) the time settings are chosen for, how far a take's own
# cycle may scale them, the lags (s) a pose's look-alike is sought at and the pose rate
# (Hz) it is sought on, and how many poses are sampled for it at most.
TEMPO_REFERENCE_S = 1.3
TEMPO_SCALE = (0.5, 2.0)
TEMPO_LAGS_S = (0.3, 6.0)
TEMPO_RATE_HZ = 30.0
TEMPO_SAMPLES = 3000
TIME_SETTINGS = ("scale_min_s", "scale_max_s", "min_segment_s", "refine_s")


def movement_period(x: np.ndarray, fps: float) -> float | None:
    """The take's typical movement cycle (s): over poses, the median lag at which a pose
    first comes back, i.e. the first local minimum of its squared distance to the poses
    ``TEMPO_LAGS_S`` later that falls below half the largest distance before it (the
    body has moved away and returned). A performer moving 10 % slower has a 10 % longer
    cycle. None when fewer than a tenth of the sampled poses come back (a take too short
    or without repetition)."""
    step = max(1, int(round(fps / TEMPO_RATE_HZ)))
    blocks = block_mean(x, step)
    rate = fps / step
    lags = np.arange(max(1, int(round(TEMPO_LAGS_S[0] * rate))),
                     int(round(TEMPO_LAGS_S[1] * rate)) + 1)
    n = len(blocks) - lags[-1]
    if n < 10:
        return None
    rows = np.arange(0, n, max(1, n // TEMPO_SAMPLES))
    d = np.empty((len(rows), len(lags)))
    for j, lag in enumerate(lags):
        diff = blocks[rows + lag] - blocks[rows]
        d[:, j] = np.einsum("ij,ij->i", diff, diff)
    low = np.zeros_like(d, dtype=bool)
    low[:, 1:-1] = (d[:, 1:-1] <= d[:, :-2]) & (d[:, 1:-1] <= d[:, 2:])
    back = low & (d < 0.5 * np.maximum.accumulate(d, axis=1))
    found = back.any(axis=1)
    if found.sum() < max(1, len(rows) // 10):
        return None
    return float(np.median(lags[np.argmax(back[found], axis=1)]) / rate)


def tempo_scale(x: np.ndarray, fps: float) -> float:
    """How much slower than ``TEMPO_REFERENCE_S`` the take moves (``movement_period``),
    within ``TEMPO_SCALE``; 1 when its cycle cannot be told."""
    period = movement_period(x, fps)
    if period is None:
        return 1.0
    return float(np.clip(period / TEMPO_REFERENCE_S, *TEMPO_SCALE))


def scaled_times(p: dict, scale: float) -> dict:
    """``p`` with ``TIME_SETTINGS`` times ``scale``, kept within their bounds."""
    from motionlib.segmenters.default import Default
    from motionlib.segmenters.default._analysis import MAX_WINDOW_SAMPLES

    if scale == 1.0:
        return p
    out = dict(p)
    for key in TIME_SETTINGS:
        param = Default.params[key]
        out[key] = float(np.clip(p[key] * scale, param.min, param.max))
    if out["rate_hz"] * out["scale_max_s"] > MAX_WINDOW_SAMPLES:
        out["scale_max_s"] = MAX_WINDOW_SAMPLES / out["rate_hz"]
        out["scale_min_s"] = min(out["scale_min_s"], out["scale_max_s"])
    return out
