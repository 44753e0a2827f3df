"""Stage 4c of the default detector: short activities, by unmatched poses.

Windows of 3-6 s see an activity shorter than about 3 s between two longer ones as one
broad peak, and one of its two boundaries is lost. Inside a repeating activity some pose
a cycle or two away always looks like the pose at hand; inside a short activity between
two others, every pose ``min_segment_s`` to 8 s away belongs to the neighbours and none
does. Where the poses of a 1.2 s stretch near a kept peak are that unlike everything
around them (``short_unmatched``, in squared kernel widths, and ``UNMATCHED_RELATIVE``
times the take's median, since in a take that never repeats itself every pose is
somewhat unmatched), the peak becomes the activity's two sides, 1.25 s either side of
the stretch's middle, each then placed as any cut. ``docs/detector/short-activities.md``
says how the constants were chosen.
"""

from __future__ import annotations

import numpy as np

from motionlib.segmenters.default._analysis import Analysis

# How far around a pose (s) its look-alikes are sought, the stretch (s) whose
# poses must all be unmatched, how far from a kept peak (s) that stretch may lie, and
# how far (s) each side of the stretch's middle its two cuts are placed from, and how
# many times the take's median unmatched level the stretch must reach as well.
UNMATCHED_CONTEXT_S = 8.0
UNMATCHED_STRETCH_S = 1.2
UNMATCHED_REACH_S = 1.5
UNMATCHED_HALF_S = 1.25
UNMATCHED_RELATIVE = 2.3


def unmatched_poses(blocks: np.ndarray, rate: float, gamma: float, nearest_s: float,
                    context_s: float = UNMATCHED_CONTEXT_S) -> np.ndarray:
    """How unlike every pose around it each pose is.

    For each block, ``gamma`` times the squared distance to the most similar block
    ``nearest_s`` to ``context_s`` seconds before or after it (in squared kernel widths:
    1 is a kernel similarity of e^-1). Inside a repeating activity some pose a cycle or
    two away always looks alike (near 0); inside an activity shorter than twice
    ``nearest_s`` between two others, every pose the search reaches belongs to the
    neighbours, and none looks alike.

    Returns
    -------
    (n_blocks,) float; 0 for a block with nothing in reach (a take too short to say).
    """
    n = len(blocks)
    out = np.full(n, np.inf)
    lo = max(1, int(np.ceil(nearest_s * rate - 1e-9)))
    hi = min(n - 1, int(np.floor(context_s * rate + 1e-9)))
    for lag in range(lo, hi + 1):
        diff = blocks[lag:] - blocks[:-lag]
        d = np.einsum("ij,ij->i", diff, diff)
        np.minimum(out[lag:], d, out=out[lag:])
        np.minimum(out[:-lag], d, out=out[:-lag])
    out[~np.isfinite(out)] = 0.0
    return gamma * out


def unmatched_of(analysis: Analysis, nearest_s: float) -> np.ndarray:
    """(n // step,) ``unmatched_poses`` of the novelty blocks of ``analysis`` (computed
    once per ``nearest_s``)."""
    return analysis.once(("unmatched", nearest_s), lambda: unmatched_poses(
        analysis.blocks, analysis.rate, analysis.gamma, nearest_s))


def unmatched_peaks(analysis: Analysis, peaks: np.ndarray, strength: np.ndarray,
                    p: dict, half_s: float = UNMATCHED_HALF_S,
                    relative: float = UNMATCHED_RELATIVE,
                    sides: dict | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Both sides of a short activity the long windows see as one peak.

    Each kept peak that ``unmatched_sides`` finds beside a short activity (``sides``
    when already computed) is replaced by that activity's two sides. Where two cuts end
    up closer than ``min_segment_s``, the earlier is kept.

    Returns
    -------
    peaks, evidence : as ``select_peaks``, sorted; both sides keep the evidence of the
        peak they replace.
    """
    if sides is None:
        sides = unmatched_sides(analysis, peaks, p, half_s, relative)
    out = sorted((side, evidence) for peak, evidence in zip(peaks.tolist(), strength.tolist(),
                                                            strict=True)
                 for side in sides.get(peak, (peak,)))
    kept: list[tuple[int, float]] = []
    for peak, evidence in out:
        if not kept or peak - kept[-1][0] >= p["min_segment_s"] * analysis.rate - 1e-9:
            kept.append((peak, evidence))
    return (np.asarray([k for k, _ in kept], dtype=peaks.dtype),
            np.asarray([e for _, e in kept], dtype=float))


def unmatched_sides(analysis: Analysis, peaks: np.ndarray, p: dict,
                    half_s: float = UNMATCHED_HALF_S,
                    relative: float = UNMATCHED_RELATIVE) -> dict[int, tuple[int, int]]:
    """The kept peaks that stand for a short activity of their own, and its two sides.

    Near each kept peak (``UNMATCHED_REACH_S``), the stretch of ``UNMATCHED_STRETCH_S``
    whose poses are, on average, least like any pose ``min_segment_s`` to
    ``UNMATCHED_CONTEXT_S`` around them (``unmatched_poses``). When that average is at
    least ``short_unmatched`` and ``relative`` times the take's median, the stretch is
    the middle of an activity of its own, too short to hold a look-alike of its own
    poses: its sides are at the stretch's middle ± ``half_s`` (placement then moves each
    to its boundary). The median is how unmatched the take's poses are anyway: in a
    take that does not repeat itself (boxing, dance, a fight) no pose has a look-alike
    and a stretch near the absolute level says nothing. Not when kept peaks lie on
    both sides of the stretch within ``scale_min_s``: the long windows have found that
    activity's two sides already, and a longer activity that does not repeat within a
    few seconds (a slow exercise) looks unmatched too. Not either when a side would lie
    closer than ``min_segment_s / 2`` to an end of the take.

    Returns
    -------
    kept peak (novelty sample) -> (first side, second side), novelty samples.
    """
    return unmatched_found(analysis, peaks, p, half_s, relative)[0]


def unmatched_found(analysis: Analysis, peaks: np.ndarray, p: dict,
                    half_s: float = UNMATCHED_HALF_S, relative: float = UNMATCHED_RELATIVE
                    ) -> tuple[dict[int, tuple[int, int]], dict[int, float]]:
    """``unmatched_sides``, and for each of its peaks how many times the take's median
    ``unmatched_poses`` its stretch reaches."""
    if len(peaks) == 0 or p["short_unmatched"] <= 0:
        return {}, {}
    firings, median = unmatched_firings(analysis, peaks, p, half_s)
    level = max(p["short_unmatched"], relative * median)
    found = {peak: firing for peak, firing in firings.items() if firing[1] >= level}
    return ({peak: sides for peak, (sides, _) in found.items()},
            {peak: at / max(median, 1e-12) for peak, (_, at) in found.items()})


def unmatched_firings(analysis: Analysis, peaks: np.ndarray, p: dict,
                      half_s: float = UNMATCHED_HALF_S
                      ) -> tuple[dict[int, tuple[tuple[int, int], float]], float]:
    """``unmatched_sides`` before its level test: each kept peak whose most unmatched
    stretch in reach passes the other tests, with its two sides and the stretch's mean
    ``unmatched_poses``; and the take's median of ``unmatched_poses`` per block."""
    rate = analysis.rate
    unmatched = unmatched_of(analysis, p["min_segment_s"])
    w = max(1, int(round(UNMATCHED_STRETCH_S * rate)))
    if len(unmatched) < w:
        return {}, 0.0
    sums = np.concatenate([[0.0], np.cumsum(unmatched)])
    stretch = (sums[w:] - sums[:-w]) / w  # mean over blocks i .. i + w - 1
    reach, half = UNMATCHED_REACH_S * rate, half_s * rate
    edge = p["min_segment_s"] * rate / 2
    out = {}
    for peak in peaks.tolist():
        lo = max(0, int(peak - reach) - w // 2)
        hi = min(len(stretch), int(peak + reach) - w // 2 + 1)
        if hi <= lo:
            continue
        start = lo + int(np.argmax(stretch[lo:hi]))
        middle = start + w // 2
        # Kept peaks on both sides within the shortest window: the long windows have
        # found this activity's two sides already.
        near = np.abs(peaks - middle) <= p["scale_min_s"] * rate
        if (near & (peaks < middle)).any() and (near & (peaks > middle)).any():
            continue
        sides = (int(round(middle - half)), int(round(middle + half)))
        if edge <= sides[0] and sides[1] <= len(unmatched) - edge:
            out[int(peak)] = (sides, float(stretch[start]))
    return out, float(np.median(unmatched))
