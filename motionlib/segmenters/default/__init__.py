"""Cutroom's own detector: multi-scale kernel novelty on a heading-invariant pose.

An activity in a take (jumping jacks, squats, walking) is a *distribution* of poses that
repeats every second or so; a boundary is where that distribution changes. The detector
is a pipeline of three public steps, each a function of the one before:

1. ``analyse(take, p) -> Analysis``: each frame becomes a pose vector that ignores where
   the performer stands and which way they face (``_features``); the poses are averaged
   into short blocks and compared, at each instant, between the past and the future
   window by the maximum mean discrepancy under one Gaussian kernel, at three window
   lengths from ``scale_min_s`` to ``scale_max_s`` (``_novelty``, ``_analysis``).
2. ``peaks(analysis, p) -> Peaks``: prominent novelty peaks become cuts, a peak whose two
   sides hold the same poses is dropped (support test), and a peak that stands for a
   short activity between two others becomes that activity's two sides (``_peaks``,
   ``_unmatched``); each cut's prominence ranks it.
3. ``place(analysis, peaks, p) -> Placement``: each cut moves, coarse to fine, to the
   best two-segment split of the poses around it, the nearest turning point of the
   motion, a nearby pause, and after a pause to the onset of the next activity
   (``_placement``), which is where annotators cut.

``Default`` runs the three steps as a registered segmenter; a variant is a subclass that
overrides a step or the hook ``window_peaks`` (the peaks before the short-activity step).

The learner (``motionlib.adapt``) describes a take by many more candidate cuts than the
detector keeps, and reads them through three more public steps, never a stage module:

- ``candidates(analysis, peaks, p)``: every peak any prominence would keep, and its
  prominence (what format-1 models choose a count among);
- ``peak_support(analysis, samples) -> (n,)``: the support test's evidence at any novelty
  samples (how much of each side the other lacks; inf near an end of the take);
- ``place_samples(analysis, samples, p, only=None) -> {step: (n,) frames}``: every
  placement step's estimate of a cut at any novelty samples, bounded by their neighbours
  as ``place`` bounds the detector's cuts.

Every other name lives in a private stage module, and the stage modules import each
other in one direction: features and novelty, then ``_placement``, ``_analysis``,
``_unmatched``, ``_peaks``.
All durations are in seconds, so the same defaults work at any frame rate. How every
setting was chosen, and the designs tried and not kept, are in ``docs/detector/``.
"""

from __future__ import annotations

import time

import numpy as np

from motionlib.segmenters.base import Param, Segmentation, Segmenter
from motionlib.segmenters.default import _analysis, _peaks, _placement, _unmatched
from motionlib.segmenters.default._analysis import MAX_WINDOW_SAMPLES, Analysis
from motionlib.segmenters.default._features import take_features
from motionlib.segmenters.default._peaks import Peaks, candidates, peak_support
from motionlib.segmenters.default._placement import (
    PLACEMENTS,
    Placement,
    place_samples,
    shipped_stage,
)

__all__ = [
    "MAX_WINDOW_SAMPLES", "PLACEMENTS", "Analysis", "Default", "Peaks", "Placement",
    "analyse", "candidates", "peak_support", "peaks", "place", "place_samples",
    "shipped_stage", "take_features",
]


class Default(Segmenter):
    name = "default"
    title = "Cutroom default (multi-scale kernel novelty)"
    description = (
        "Compares the distribution of heading-invariant poses before and after each "
        "instant (kernel MMD at 3-6 s windows); strong peaks become cuts, placed at the "
        "best two-segment split, then at the nearest turning point or pause of the "
        "motion. Parameters are in seconds and work at any frame rate."
    )
    params = {
        "threshold": Param(
            "float", 0.1, 0.0, 2.0,
            "Minimum mean MMD² (0 = same poses, 2 = disjoint) for a peak to become a cut.",
        ),
        "min_segment_s": Param("float", 1.5, 0.1, 60.0, "Minimum time between two cuts (s)."),
        # Cost grows with the square of the samples in a window (rate_hz * scale_max_s,
        # at most MAX_WINDOW_SAMPLES): the bounds keep a one-hour take within minutes.
        "scale_min_s": Param("float", 3.0, 0.2, 20.0, "Shortest comparison window (s)."),
        "scale_max_s": Param("float", 6.0, 0.2, 20.0, "Longest comparison window (s)."),
        "bandwidth": Param(
            "float", 0.3, 0.01, 100.0,
            "Kernel width² as a multiple of the median squared pose distance.",
        ),
        "velocity_s": Param(
            "float", 0.0, 0.0, 5.0,
            "Weight (s) of joint velocities beside the poses; 0 compares poses only.",
        ),
        "refine_s": Param(
            "float", 0.5, 0.0, 5.0,
            "How far (s) each placement step (best split, turning point, pause) may move a cut.",
        ),
        "rate_hz": Param("float", 10.0, 1.0, 60.0, "Pose rate (Hz) for the novelty curve."),
        "prominence": Param(
            "float", 0.1, 0.0, 2.0,
            "Minimum rise of a peak above the higher of the two valleys beside it (MMD²).",
        ),
        "onset": Param(
            "bool", True, 0, 1,
            "Move a cut that falls in a pause to its end, the onset of the next activity.",
        ),
        "short_unmatched": Param(
            "float", 1.0, 0.0, 100.0,
            "Cut both sides of a short activity where the poses near a cut are this far "
            "(squared kernel widths) from every pose min_segment_s to 8 s around them "
            "(0 = off).",
        ),
        "support": Param(
            "float", 0.5, 0.0, 100.0,
            "Drop a peak where every pose of the 4 s on either side has a look-alike on "
            "the other side: the mean squared distance (squared kernel widths) from each "
            "pose to its nearest across the peak stays below this on both sides (0 = off).",
        ),
    }
    # The unmatched-poses step's half-width (s) and take-median guard (``_unmatched``).
    unmatched_half_s = _unmatched.UNMATCHED_HALF_S
    unmatched_relative = _unmatched.UNMATCHED_RELATIVE

    @classmethod
    def validate_params(cls, values):
        return _analysis.within_window_limit(super().validate_params(values))

    def _segment(self, take, **p) -> Segmentation:
        analysis = self.analyse(take, p)
        if analysis is None:
            return _analysis.empty_segmentation(take)
        t0 = time.perf_counter()
        found = self.peaks(analysis, p)
        placed = self.place(analysis, found, p)
        result = analysis.segmentation(placed.cuts, found.confidence(p), placed.speed)
        result.timings["cuts"] = time.perf_counter() - t0
        return result

    @classmethod
    def analyse(cls, take, p: dict) -> Analysis | None:
        """Step 1: pose stream, kernel and novelty curve of ``take`` (None if it is too
        short to compare anything). ``p`` are validated parameters; ParamError names a
        window setting that cannot work."""
        return _analysis.analyse(take, p)

    @classmethod
    def peaks(cls, analysis: Analysis, p: dict) -> Peaks:
        """Step 2: the novelty peaks that become cuts, with their evidence."""
        found, evidence = cls.window_peaks(analysis, p)
        return _peaks.split_short(analysis, found, evidence, p, cls.unmatched_half_s,
                                  cls.unmatched_relative)

    @classmethod
    def window_peaks(cls, analysis: Analysis, p: dict) -> tuple[np.ndarray, np.ndarray]:
        """The peaks the novelty windows choose and the support test keeps, before the
        short-activity step: novelty samples and their prominence. A subclass that adds
        or drops candidates overrides this."""
        return _peaks.window_peaks(analysis, p)

    @classmethod
    def place(cls, analysis: Analysis, found: Peaks, p: dict) -> Placement:
        """Step 3: where each cut of ``found`` goes (frames of ``analysis.x``)."""
        return _placement.place(analysis, found, p)


analyse = Default.analyse
peaks = Default.peaks
place = Default.place
