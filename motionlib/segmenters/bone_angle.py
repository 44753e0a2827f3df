"""Bone-angle candidates (2011 journal paper on interactive segmentation of 3D human motion).

Per frame, the angles between the 8 limb bones and the centre bone (root -> chest)
form an 8-vector; its norm Q is low-pass filtered; every local extremum whose swing on
one side is small against the swing on the other (``min <= param * max``) becomes a
candidate cut. This is the reference method, reproduced as published.
"""

from __future__ import annotations

import time

import numpy as np

from motionlib import features
from motionlib.segmenters.base import Param, Segmentation, Segmenter, full_length, take_positions


class BoneAngle(Segmenter):
    name = "bone_angle"
    title = "Bone angles (2011 paper)"
    description = (
        "Norm of the 8 limb-bone angles to the spine, low-pass filtered; extrema whose "
        "swing is one-sided become candidates. Finds most boundaries, proposes many."
    )
    params = {
        "param": Param(
            "float", 0.5, 0.0, 1.0,
            "Swing test: an extremum is a candidate when the smaller swing is at most "
            "this fraction of the larger one.",
        ),
        "cutoff_hz": Param(
            "float", 1.0, 0.05, 30.0,
            "Low-pass cutoff (Hz) applied to the angle norm before finding extrema.",
        ),
    }

    def _segment(self, take, *, param: float, cutoff_hz: float) -> Segmentation:
        t0 = time.perf_counter()
        positions, joints, first = take_positions(take)
        t1 = time.perf_counter()
        q = np.linalg.norm(features.bone_angles(positions, joints), axis=1)
        smooth = features.lowpass(q, fps=take.fps, cutoff_hz=cutoff_hz)
        idx, _ = features.local_extrema(smooth)
        passed, strength = features.swing_test(smooth, idx, param)
        t2 = time.perf_counter()
        return Segmentation(
            cuts=idx[passed] + first,
            confidence=strength[passed],
            signals={
                "bone_angle_norm": full_length(q, first),
                "bone_angle_norm_smooth": full_length(smooth, first),
            },
            timings={"kinematics": t1 - t0, "detect": t2 - t1},
        )
