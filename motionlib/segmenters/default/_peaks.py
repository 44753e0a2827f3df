"""Stage 4 of the default detector: which novelty peaks become cuts.

A peak of the mean novelty curve becomes a cut when it is high enough (``threshold``),
stands above the higher of the valleys beside it (``prominence``: what tells a boundary
from a wobble on the shoulder of a broad peak) and lies ``min_segment_s`` from a higher
peak; its prominence is its evidence, and confidence ``q / (q + prominence)`` ranks the
candidates. The support test (``support``) then drops a peak whose two sides hold the
same poses: windows over a few cycles of one slow movement see its phases in other
proportions and peak there, while at a boundary one side takes poses the other never
does. ``docs/detector/support.md`` says how its level and windows were chosen.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import find_peaks
from scipy.spatial.distance import cdist

from motionlib.segmenters.default._analysis import Analysis
from motionlib.segmenters.default._unmatched import (
    UNMATCHED_HALF_S,
    UNMATCHED_RELATIVE,
    unmatched_found,
    unmatched_peaks,
    unmatched_sides,
)


@dataclass(frozen=True)
class Peaks:
    """The novelty peaks that become cuts (stage 4).

    samples : (n,) int novelty samples of the cuts, increasing (``Analysis.peak_frames``
        turns them into frames).
    evidence : (n,) float, each cut's prominence (MMD²); ``confidence`` ranks by it.
    sides : the peaks the windows found that the unmatched-poses step replaced by the two
        sides of a short activity: peak sample -> (first side, second side).
    unmatched : for each peak of ``sides``, how many times the take's median unmatched
        level the poses between its sides reach (the step's evidence).
    """

    samples: np.ndarray
    evidence: np.ndarray
    sides: dict[int, tuple[int, int]] = field(default_factory=dict)
    unmatched: dict[int, float] = field(default_factory=dict)

    def confidence(self, p: dict) -> np.ndarray:
        """(n,) confidence in [0, 1): 0.5 at the ``prominence`` setting."""
        half = p["prominence"] if p["prominence"] > 0 else p["threshold"]
        return self.evidence / (self.evidence + max(half, 1e-12))


def select_peaks(novelty: np.ndarray, rate: float, p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Novelty peaks that become cuts, and each one's evidence (its prominence).

    A peak must reach ``threshold``, stand ``prominence`` above the higher of the
    valleys beside it, and lie ``min_segment_s`` from a higher peak.
    """
    padded = np.concatenate([[0.0], novelty, [0.0]])
    distance = max(1, int(round(p["min_segment_s"] * rate)))
    peaks, props = find_peaks(padded, height=max(p["threshold"], 1e-12),
                              distance=distance, prominence=p["prominence"])
    peaks, prominence = peaks - 1, props["prominences"]
    # The first and last segment may be shorter than the others, but not absurdly:
    # at least half the minimum segment.
    edge = p["min_segment_s"] * rate / 2
    keep = (peaks + 0.5 >= edge) & (len(novelty) - peaks - 0.5 >= edge)
    return peaks[keep], prominence[keep]


def window_peaks(analysis: Analysis, p: dict) -> tuple[np.ndarray, np.ndarray]:
    """The peaks the novelty windows choose and the support test keeps, and their
    evidence."""
    peaks, strength = select_peaks(analysis.novelty, analysis.rate, p)
    keep = supported_peaks(analysis, peaks, p)
    return peaks[keep], strength[keep]


def candidates(analysis: Analysis, found: Peaks, p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Every peak that would become a cut at some ``prominence``, and its prominence.

    The peaks of any prominence that the support test keeps, a short activity of
    ``found`` (``Peaks.sides``) exempted as ``peaks`` exempts it: what adapting the
    count to a studio's cuts chooses among (``motionlib.adapt``).
    """
    peaks, prominence = select_peaks(analysis.novelty, analysis.rate, {**p, "prominence": 0.0})
    keep = supported_peaks(analysis, peaks, p, short=found.sides)
    return peaks[keep], prominence[keep]


# The support test: the stretch (s) on each side of a peak whose poses are compared, and
# the gap (s) left out around the peak itself, where the passage between two activities
# mixes both.
SUPPORT_SIDE_S = 4.0
SUPPORT_GAP_S = 0.25


def cross_support(blocks: np.ndarray, peaks: np.ndarray, rate: float, gamma: float,
                  side_s: float = SUPPORT_SIDE_S, gap_s: float = SUPPORT_GAP_S) -> np.ndarray:
    """How much of each side of each peak the other side lacks.

    For the poses (blocks) of the ``side_s`` after a peak (beyond ``gap_s``), the mean of
    ``gamma`` times the squared distance to the nearest pose of the ``side_s`` before it,
    and the same the other way; the larger of the two. A boundary between two activities
    leaves poses on at least one side that the other side never takes (high); a peak
    inside one activity whose windows caught different phases or proportions of the same
    movement has every pose matched across it (near 0), whatever the proportions.

    Returns
    -------
    (len(peaks),) float; inf where a side holds fewer than 3 blocks (a peak near an end
    of the take: nothing to say).
    """
    n = len(blocks)
    side = max(3, int(round(side_s * rate)))
    gap = int(round(gap_s * rate))
    out = np.full(len(peaks), np.inf)
    for i, k in enumerate(np.asarray(peaks, dtype=np.int64).tolist()):
        after = blocks[min(n, k + 1 + gap):min(n, k + 1 + gap + side)]
        before = blocks[max(0, k - gap - side):max(0, k - gap)]
        if len(after) < 3 or len(before) < 3:
            continue
        d = gamma * cdist(after, before, "sqeuclidean")
        out[i] = max(d.min(axis=1).mean(), d.min(axis=0).mean())
    return out


def peak_support(analysis: Analysis, peaks: np.ndarray) -> np.ndarray:
    """(len(peaks),) ``cross_support`` of each novelty sample of ``analysis`` (each
    sample's computed once: the support test and the learner's evidence read the same)."""
    known = analysis.once("support", dict)
    peaks = np.asarray(peaks).tolist()
    new = [k for k in dict.fromkeys(peaks) if k not in known]
    if new:
        known.update(zip(new, cross_support(analysis.blocks, np.asarray(new), analysis.rate,
                                            analysis.gamma).tolist(), strict=True))
    return np.asarray([known[k] for k in peaks], dtype=float)


def supported_peaks(analysis: Analysis, peaks: np.ndarray, p: dict,
                    short: dict | None = None) -> np.ndarray:
    """(len(peaks),) bool: the peaks the support test keeps (all of them with
    ``support`` 0): those whose ``cross_support`` reaches ``p["support"]``, and those the
    unmatched-poses step reads as a short activity (``short``, its
    ``unmatched_sides``, computed on ``peaks`` when not given): one between two alike
    activities straddles the peak, each side holds part of it, and every pose is matched
    across."""
    if p["support"] <= 0:
        return np.ones(len(peaks), dtype=bool)
    keep = peak_support(analysis, peaks) >= p["support"]
    if not keep.all():
        short = unmatched_sides(analysis, peaks, p) if short is None else short
        keep |= np.isin(peaks, list(short))
    return keep


def split_short(analysis: Analysis, peaks: np.ndarray, strength: np.ndarray, p: dict,
                half_s: float = UNMATCHED_HALF_S, relative: float = UNMATCHED_RELATIVE
                ) -> Peaks:
    """The cuts of the kept ``peaks`` (evidence ``strength``): with ``short_unmatched``,
    each peak the long windows saw where a short activity lies between two others becomes
    that activity's two sides (``unmatched_sides``, with its half-width and take-median
    guard)."""
    sides, levels = unmatched_found(analysis, peaks, p, half_s, relative)
    if p["short_unmatched"] > 0:
        peaks, strength = unmatched_peaks(analysis, peaks, strength, p, sides=sides)
    return Peaks(peaks, strength, sides, levels)
