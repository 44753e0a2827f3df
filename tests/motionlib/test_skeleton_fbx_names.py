"""Joint names of FBX rigs (Mixamo, MotionBuilder HumanIK, Blender) map to the body parts."""

import numpy as np
import pytest

import motionlib
from motionlib.errors import CaptureError
from motionlib.skeleton import Skeleton


def chain(names):
    """A skeleton with the given joints, each the child of the one before (the tree shape does
    not matter to name matching)."""
    n = len(names)
    return Skeleton(names=names, parents=np.arange(-1, n - 1), offsets=np.zeros((n, 3)),
                    channels=[("Zrotation",)] * n, rotation_orders=["Z"] * n)


SIDES = ["Arm", "ForeArm", "Hand", "UpLeg", "Leg", "Foot", "ToeBase"]


def test_it_maps_motionbuilder_humanik_names_under_a_character_prefix():
    names = ["Character1_" + n for n in ["Hips", "Spine", "Spine1", "Spine2", "Neck", "Head"]]
    names += [f"Character1_{side}{part}" for side in ("Left", "Right") for part in SIDES]
    parts = motionlib.canonical_joints(chain(names))
    assert parts["Character1_Spine2"] == "chest"
    assert parts["Character1_RightForeArm"] == "right_elbow"
    assert set(parts.values()) == set(motionlib.CANONICAL_PARTS)


def test_it_maps_mixamo_names_with_their_namespace():
    names = ["mixamorig:" + n for n in ["Hips", "Spine", "Spine1", "Spine2", "Neck", "Head"]]
    names += [f"mixamorig:{side}{part}" for side in ("Left", "Right") for part in SIDES]
    parts = motionlib.canonical_joints(chain(names))
    assert parts["mixamorig:LeftUpLeg"] == "left_hip"
    assert set(parts.values()) == set(motionlib.CANONICAL_PARTS)


def test_it_maps_blenders_human_metarig_names():
    names = ["spine", "spine.001", "spine.002", "spine.003", "spine.004", "spine.005",
             "spine.006"]
    names += [f"{part}.{side}" for side in ("L", "R")
              for part in ("upper_arm", "forearm", "hand", "thigh", "shin", "foot", "toe")]
    parts = motionlib.canonical_joints(chain(names))
    assert (parts["spine"], parts["spine.003"], parts["spine.006"]) == ("root", "chest", "head")
    assert (parts["forearm.R"], parts["shin.L"]) == ("right_elbow", "left_knee")
    assert set(parts.values()) == set(motionlib.CANONICAL_PARTS)


def test_it_maps_rigify_deform_bones():
    names = ["DEF-spine", "DEF-spine.001", "DEF-spine.003", "DEF-spine.004", "DEF-spine.006"]
    names += [f"DEF-{part}.{side}" for side in ("L", "R")
              for part in ("upper_arm", "forearm", "hand", "thigh", "shin", "foot")]
    parts = motionlib.canonical_joints(chain(names))
    assert parts["DEF-thigh.R"] == "right_hip"


def test_it_names_the_fbx_namings_when_a_rig_is_unknown():
    with pytest.raises(CaptureError, match="MotionBuilder HumanIK, Blender"):
        motionlib.canonical_indices(chain(["a", "b", "c"]))
