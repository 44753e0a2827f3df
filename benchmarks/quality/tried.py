"""Options of the default detector tried and not shipped, as a subclass the bench scores.

:class:`Tried` is the shipped detector (``segmenters.default.Default``) with three more
parameters, each off at its default, so that the bench can score them out of sample
beside the shipped grid (the ``tried/loo`` row, ``tuning.TRIED``):

- ``tempo``: the time settings (windows, minimum segment, placement reach) scaled by the
  take's own movement cycle (``movement_period``) over ``TEMPO_REFERENCE_S``, so that a
  slower performer gets longer windows;
- ``short_activity``: the far side of an activity too short for the long windows, where
  windows of ``min_segment_s`` show a prominent peak at both the kept peak and a shoulder
  of it (``short_activity_peaks``);
- ``short_uniformity``: with ``short_activity``, such a cut only where the stretch
  between the two looks like one activity (``mixing``).

Each lost out of sample, which is why none is a parameter of the shipped detector;
``docs/detector/tempo.md`` and ``docs/detector/short-activities.md`` record how they
scored. A new experiment is such a subclass or option here, never a shipped parameter.
It uses only the detector's public pipeline: ``Tried`` overrides ``analyse`` (tempo),
``window_peaks`` (short activities), and ``peaks`` and ``place`` (the scaled settings).
"""

from __future__ import annotations

from dataclasses import dataclass, fields

import numpy as np
from scipy.signal import find_peaks
from scipy.spatial.distance import cdist

from motionlib.segmenters.base import Param
from motionlib.segmenters.default import (
    MAX_WINDOW_SAMPLES,
    Analysis,
    Default,
    Peaks,
    Placement,
    take_features,
)


def block_mean(x: np.ndarray, step: int) -> np.ndarray:
    """Average consecutive blocks of ``step`` frames: (n, d) -> (n // step, d)."""
    n = len(x) // step
    return x[: n * step].reshape(n, step, -1).mean(axis=1)


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


# How far (s) a short-window peak may lie from the long-window peak or shoulder it confirms.
SHORT_PEAK_TOLERANCE_S = 0.5


def short_activity_peaks(analysis: Analysis, peaks: np.ndarray, strength: np.ndarray,
                         p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Add the far side of activities too short for the long windows.

    Between two long activities, windows of ``scale_min_s`` and more see a short one as
    a single broad peak: the boundary it does not pick is at most a *shoulder* (a local
    maximum without the prominence) at most ``scale_min_s`` away. Windows of
    ``min_segment_s`` (the shortest activity to find) resolve the two. Such a shoulder
    becomes a cut, at its short-window peak, when the short-window novelty has a peak
    within ``SHORT_PEAK_TOLERANCE_S`` of both the shoulder and the kept peak, each
    ``short_activity`` times as prominent as the median short-window peak inside the
    activities (farther than ``scale_min_s / 2`` from every kept peak) and at least
    ``prominence``: short windows also fire on changes within an activity, so only a
    pair that stands well above the take's own such changes counts. With
    ``short_uniformity`` the stretch between the two must also look like one activity
    (``mixing`` at most that), not like the passage from one activity into the next.

    Returns
    -------
    peaks, evidence : as ``Default.window_peaks``, sorted; an added peak's evidence is the
        ``prominence`` setting (confidence 0.5, the weakest peak kept on its own).
    """
    if len(peaks) == 0:
        return peaks, strength
    rate, novelty = analysis.rate, analysis.novelty
    short = analysis.short_novelty(p["min_segment_s"])
    tops, props = find_peaks(np.concatenate([[0.0], short, [0.0]]), prominence=0.0)
    tops, prominence = tops - 1, props["prominences"]
    reach = p["scale_min_s"] * rate
    inside = np.abs(tops[:, None] - peaks[None, :]).min(axis=1) > reach / 2
    if not inside.any():
        return peaks, strength
    level = max(p["short_activity"] * float(np.median(prominence[inside])), p["prominence"])
    strong = tops[prominence >= level]
    tolerance = SHORT_PEAK_TOLERANCE_S * rate
    distance = p["min_segment_s"] * rate

    def confirmed(sample: int) -> int | None:
        if not len(strong):
            return None
        best = strong[np.argmin(np.abs(strong - sample))]
        return int(best) if abs(best - sample) <= tolerance else None

    shoulders, _ = find_peaks(np.concatenate([[0.0], novelty, [0.0]]),
                              height=max(p["threshold"], 1e-12))
    cuts = list(peaks)
    for shoulder in shoulders - 1:
        kept = int(peaks[np.argmin(np.abs(peaks - shoulder))])
        if np.abs(np.asarray(cuts) - shoulder).min() < distance or \
                abs(shoulder - kept) > reach or confirmed(kept) is None:
            continue
        side = confirmed(shoulder)
        if side is None or np.abs(np.asarray(cuts) - side).min() < distance:
            continue
        if p["short_uniformity"] > 0 and not (
                mixing(analysis, kept, side, int(round(distance))) <= p["short_uniformity"]):
            continue
        cuts.append(side)
    added = np.asarray(cuts[len(peaks):], dtype=np.int64)
    order = np.argsort(np.concatenate([peaks, added]), kind="stable")
    evidence = np.concatenate([strength, np.full(len(added), p["prominence"])])
    return np.concatenate([peaks, added])[order], evidence[order]


def mixing(analysis: Analysis, a: int, b: int, context: int) -> float:
    """How unlike itself the stretch between novelty samples ``a`` and ``b`` is.

    MMD² between the stretch's two halves over MMD² between the stretch and the nearer-
    looking of its neighbours (``context`` samples each side), on the novelty blocks and
    kernel. An activity repeats, so its halves look alike (near 0); the passage from one
    activity into the next morphs, so its halves differ about as much as it differs from
    its neighbours (near 1 and above). NaN when a part is too short to compare.
    """
    lo, hi = sorted((a, b))
    blocks = analysis.blocks
    middle, before, after = blocks[lo:hi], blocks[max(0, lo - context):lo], blocks[hi:hi + context]
    if len(middle) < 4 or min(len(before), len(after)) < 2:
        return float("nan")
    half = len(middle) // 2
    inner = mmd(middle[:half], middle[half:], analysis.gamma)
    return inner / max(min(mmd(before, middle, analysis.gamma),
                           mmd(middle, after, analysis.gamma)), 1e-12)


def mmd(x: np.ndarray, y: np.ndarray, gamma: float) -> float:
    """Biased MMD² between the samples ``x`` (n, d) and ``y`` (m, d), Gaussian kernel."""
    def mean_k(u, v):
        return float(np.exp(-gamma * cdist(u, v, "sqeuclidean")).mean())
    return mean_k(x, x) + mean_k(y, y) - 2 * mean_k(x, y)


@dataclass
class PacedAnalysis(Analysis):
    """An ``Analysis`` made with the time settings scaled by ``tempo`` (1: as given)."""

    tempo: float = 1.0


def paced(analysis: Analysis, p: dict) -> dict:
    """``p`` with its time settings scaled as ``analysis``'s windows were."""
    return scaled_times(p, getattr(analysis, "tempo", 1.0))


class Tried(Default):
    """The default detector with the options tried and not shipped (all off by default:
    then it cuts exactly as ``Default``). Not registered: only the bench runs it."""

    name = "tried"
    title = "Cutroom default with the options tried and not shipped"
    params = {
        **Default.params,
        "short_activity": Param(
            "float", 0.0, 0.0, 100.0,
            "Also cut the far side of an activity shorter than the shortest window when "
            "min_segment_s windows show it this many times more clearly than the "
            "changes inside activities (0 = off).",
        ),
        "short_uniformity": Param(
            "float", 0.0, 0.0, 10.0,
            "With short_activity: keep such a cut only if the short activity's two halves "
            "differ at most this fraction as much as it differs from its neighbours "
            "(0 = no test).",
        ),
        "tempo": Param(
            "bool", False, 0, 1,
            "Scale the windows, the minimum segment and the placement reach by the "
            "take's movement cycle (a slower performer gets longer windows).",
        ),
    }

    @classmethod
    def analyse(cls, take, p: dict) -> Analysis | None:
        # Bad scales are refused before any scaling, as the shipped detector refuses them.
        if not p["tempo"] or p["scale_max_s"] < p["scale_min_s"]:
            return super().analyse(take, p)
        x, _ = take_features(take, velocity_s=p["velocity_s"])
        scale = tempo_scale(x, float(take.fps))
        analysis = super().analyse(take, scaled_times(p, scale))
        if analysis is None:
            return None
        return PacedAnalysis(**{f.name: getattr(analysis, f.name) for f in fields(Analysis)},
                             tempo=scale)

    @classmethod
    def peaks(cls, analysis: Analysis, p: dict) -> Peaks:
        return super().peaks(analysis, paced(analysis, p))

    @classmethod
    def window_peaks(cls, analysis: Analysis, p: dict) -> tuple[np.ndarray, np.ndarray]:
        found, evidence = super().window_peaks(analysis, p)
        if p["short_activity"] > 0:
            found, evidence = short_activity_peaks(analysis, found, evidence, p)
        return found, evidence

    @classmethod
    def place(cls, analysis: Analysis, found: Peaks, p: dict) -> Placement:
        return super().place(analysis, found, paced(analysis, p))


def detector(params: dict) -> type[Default]:
    """The class that takes ``params``: :class:`Tried` when they set a tried option, else
    the shipped ``Default``."""
    return Tried if any(key in params and key not in Default.params for key in Tried.params) \
        else Default
