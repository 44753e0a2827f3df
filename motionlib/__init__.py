"""motionlib: reading, kinematics and segmentation of motion-capture takes (no Django here).

>>> import motionlib
>>> take = motionlib.read("13_29.amc", asf="13.asf")      # or motionlib.read("13_29.bvh")
>>> take.fps, take.n_frames, take.skeleton.n_joints
(120.0, 4592, 31)
>>> positions = motionlib.forward_kinematics(take)        # (n_frames, n_joints, 3), Y up
>>> at = motionlib.canonical_indices(take)                # {"left_knee": 3, ...}
>>> knee = positions[:, at["left_knee"]]
>>> motionlib.write_bvh(take, "clip.bvh", start=120, stop=480)
>>> synthetic, segments = motionlib.synth.generate(seed=0, duration=60.0)

Bad files raise :class:`CaptureError` (a ``ValueError``) naming the file, line and value.
"""

from motionlib import synth
from motionlib.errors import CaptureError
from motionlib.io import read, write_bvh
from motionlib.kinematics import forward_kinematics, skeleton_height
from motionlib.skeleton import CANONICAL_PARTS, Skeleton, canonical_indices, canonical_joints
from motionlib.take import Take

__all__ = [
    "CANONICAL_PARTS", "CaptureError", "Skeleton", "Take", "canonical_indices",
    "canonical_joints", "forward_kinematics", "read", "skeleton_height", "synth", "write_bvh",
]
