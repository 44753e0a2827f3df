"""motionlib: reading, kinematics and segmentation of motion-capture takes (no Django here)."""

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
