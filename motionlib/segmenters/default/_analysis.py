"""Stage 3 of the default detector: one take's pose stream, kernel and novelty curve.

The pose stream is averaged into blocks (``rate_hz``) for speed; one Gaussian kernel,
its width from the median heuristic (``bandwidth`` times the median squared distance
between blocks), serves detection and placement; the novelty is the mean MMD² over three
windows evenly spread from ``scale_min_s`` to ``scale_max_s`` (a window must span several
repetitions of a periodic activity, about 1 Hz for most exercises, so that the poses of
one activity look alike from window to window). An ``Analysis`` also keeps, computed
once each, the curves the later stages read (``once``); the stages compute them, so that
this module imports none of theirs.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np

from motionlib.segmenters.base import ParamError, Segmentation, full_length
from motionlib.segmenters.default._features import block_mean, median_sq_distance, take_features
from motionlib.segmenters.default._novelty import mirrored_novelties, window_widths
from motionlib.segmenters.default._placement import pose_speeds

# Poses in the longest comparison window (rate_hz * scale_max_s); the cost of a take
# grows with its square.
MAX_WINDOW_SAMPLES = 600


def within_window_limit(p: dict) -> dict:
    """``p``, refused with a ParamError when a window would hold more than
    ``MAX_WINDOW_SAMPLES`` poses."""
    if p["rate_hz"] * p["scale_max_s"] > MAX_WINDOW_SAMPLES:
        raise ParamError(
            f"rate_hz: rate_hz * scale_max_s must be at most {MAX_WINDOW_SAMPLES} poses "
            f"per window, got {p['rate_hz']:g} * {p['scale_max_s']:g}"
        )
    return p


@dataclass
class Analysis:
    """What the default detector computes before choosing cuts.

    x : (n, d) pose features of frames ``first ..`` at ``fps``; step : frames per novelty
    block; gamma : kernel 1 / bandwidth²; novelty : (n // step,) mean MMD² per block.
    """

    x: np.ndarray
    fps: float
    step: int
    first: int
    gamma: float
    novelty: np.ndarray
    timings: dict[str, float]
    # Curves of the pose blocks and kernel, computed once (``once``); none depends on the
    # novelty windows, so ``with_windows`` shares them.
    _short: dict = field(default_factory=dict, repr=False)

    def once(self, key, compute):
        """``compute()``, computed the first time ``key`` is asked for and kept: for what
        the later stages read of the pose blocks and kernel (unmatched poses, each peak's
        support), which no novelty window changes, so the copies ``with_windows`` makes
        share it."""
        if key not in self._short:
            self._short[key] = compute()
        return self._short[key]

    @property
    def rate(self) -> float:
        """Novelty samples per second."""
        return self.fps / self.step

    @property
    def blocks(self) -> np.ndarray:
        """(n // step, d) the poses averaged into novelty blocks (computed once)."""
        if "blocks" not in self._short:
            self._short["blocks"] = block_mean(self.x, self.step)
        return self._short["blocks"]

    def short_novelty(self, window_s: float) -> np.ndarray:
        """(n // step,) MMD² with one window of ``window_s`` seconds (computed once)."""
        w = max(1, int(round(window_s * self.rate)))
        if w not in self._short:
            blocks = self.blocks
            self._short[w] = mirrored_novelties(blocks, [w], self.gamma)[0] \
                if len(blocks) >= 4 else np.zeros(len(blocks))
        return self._short[w]

    @property
    def speeds(self) -> tuple[np.ndarray, np.ndarray]:
        """``pose_speeds`` of the pose stream (computed once)."""
        if "speeds" not in self._short:
            self._short["speeds"] = pose_speeds(self.x, self.fps)
        return self._short["speeds"]

    def with_windows(self, *windows: tuple[float, float]) -> list[Analysis]:
        """The same pose stream and kernel with the novelty at other window lengths.

        ``windows`` are ``(scale_min_s, scale_max_s)`` pairs; all their window lengths
        share one pass over the lags (``mirrored_novelties``).
        """
        widths = [window_widths(lo, hi, self.rate) for lo, hi in windows]
        union = sorted({w for ws in widths for w in ws})
        curves = dict(zip(union, mirrored_novelties(self.blocks, union, self.gamma),
                          strict=True))
        return [replace(self, novelty=np.mean([curves[w] for w in ws], axis=0))
                for ws in widths]

    def peak_frames(self, peaks: np.ndarray) -> np.ndarray:
        """Novelty sample indices -> frames of ``x`` (block centres)."""
        return np.asarray(peaks, dtype=np.int64) * self.step + self.step // 2

    def segmentation(self, cuts: np.ndarray, confidence: np.ndarray,
                     speed: np.ndarray) -> Segmentation:
        """The result for cuts given in frames of ``x``."""
        centres = np.arange(len(self.novelty)) * self.step + self.step / 2
        curve = np.interp(np.arange(len(self.x)), centres, self.novelty)
        return Segmentation(
            cuts=np.asarray(cuts, dtype=np.int64) + self.first,
            confidence=confidence,
            signals={"novelty": full_length(curve, self.first),
                     "speed": full_length(speed, self.first)},
            timings=dict(self.timings),
        )


def empty_segmentation(take) -> Segmentation:
    """No cuts, for a take too short to compare anything."""
    return Segmentation(np.zeros(0, np.int64), np.zeros(0),
                        {"novelty": np.zeros(take.n_frames)})


def analyse(take, p: dict) -> Analysis | None:
    """Pose stream, kernel and novelty curve of ``take`` (None if it is too short).

    ``p`` are validated parameters; a scale error raises ParamError.
    """
    if p["scale_max_s"] < p["scale_min_s"]:
        raise ParamError(
            f"scale_max_s: must be at least scale_min_s ({p['scale_min_s']:g}), "
            f"got {p['scale_max_s']:g}"
        )
    fps = float(take.fps)
    t0 = time.perf_counter()
    x, first = take_features(take, velocity_s=p["velocity_s"])
    t1 = time.perf_counter()
    step = max(1, int(round(fps / p["rate_hz"])))
    if len(x) < 2 * step:  # too short to compare anything: no cuts
        return None
    blocks = block_mean(x, step)
    # One kernel for detection and placement, its width from the median heuristic.
    gamma = 1.0 / max(p["bandwidth"] * median_sq_distance(blocks), 1e-12)
    novelty = _novelty(blocks, fps / step, gamma, p)
    t2 = time.perf_counter()
    return Analysis(x=x, fps=fps, step=step, first=first, gamma=gamma, novelty=novelty,
                    timings={"kinematics": t1 - t0, "novelty": t2 - t1},
                    _short={"blocks": blocks})


def _novelty(x: np.ndarray, rate: float, gamma: float, p: dict) -> np.ndarray:
    """Mean MMD² over window lengths evenly spread between the two scales."""
    if len(x) < 4:
        return np.zeros(len(x))
    widths = window_widths(p["scale_min_s"], p["scale_max_s"], rate)
    return np.mean(mirrored_novelties(x, widths, gamma), axis=0)
