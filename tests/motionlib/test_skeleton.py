"""Canonical body parts for the joint namings we meet: CMU ASF, cgspeed BVH, DAZ, Mixamo."""

import numpy as np
import pytest

import motionlib
from motionlib import CaptureError, Skeleton, Take


def take_with(names: list[str]) -> Take:
    n = len(names)
    sk = Skeleton(names=names, parents=[-1] + [0] * (n - 1), offsets=np.zeros((n, 3)),
                  channels=[()] * n, rotation_orders=[""] * n)
    return Take(name="t", format="bvh", fps=30.0, frame_time=1 / 30, channels=np.zeros((1, 0)),
                skeleton=sk)


MIXAMO = ["Hips", "Spine", "Spine1", "Spine2", "Neck", "Head", "LeftShoulder", "LeftArm",
          "LeftForeArm", "LeftHand", "RightShoulder", "RightArm", "RightForeArm", "RightHand",
          "LeftUpLeg", "LeftLeg", "LeftFoot", "LeftToeBase", "RightUpLeg", "RightLeg",
          "RightFoot", "RightToeBase"]
DAZ = ["hip", "abdomen", "chest", "neck", "head", "lCollar", "lShldr", "lForeArm", "lHand",
       "rCollar", "rShldr", "rForeArm", "rHand", "lButtock", "lThigh", "lShin", "lFoot",
       "rButtock", "rThigh", "rShin", "rFoot"]


def test_it_maps_cgspeed_bvh_names(bvh_13_29):
    joints = motionlib.canonical_joints(motionlib.read(bvh_13_29))
    assert joints["Hips"] == "root" and joints["Spine1"] == "chest"
    assert joints["LeftUpLeg"] == "left_hip" and joints["RightForeArm"] == "right_elbow"
    assert joints["LeftToeBase"] == "left_toe" and "LHipJoint" not in joints


def test_it_maps_cmu_asf_bone_names(amc_13_29):
    take = motionlib.read(amc_13_29[0], asf=amc_13_29[1])
    at = motionlib.canonical_indices(take)
    names = take.skeleton.names
    assert names[at["left_hip"]] == "lfemur" and names[at["left_knee"]] == "ltibia"
    assert names[at["right_wrist"]] == "rwrist" and names[at["chest"]] == "thorax"


def test_it_maps_mixamo_names_with_their_namespace():
    take = take_with([f"mixamorig:{n}" for n in MIXAMO])
    joints = motionlib.canonical_joints(take)
    assert joints["mixamorig:Spine2"] == "chest" and joints["mixamorig:Spine1"] == "spine"
    assert joints["mixamorig:LeftUpLeg"] == "left_hip"
    assert set(joints.values()) == set(motionlib.CANONICAL_PARTS)


def test_it_maps_daz_names_without_toes():
    at = motionlib.canonical_indices(take_with(DAZ))
    assert DAZ[at["left_hip"]] == "lThigh" and DAZ[at["right_shoulder"]] == "rShldr"
    assert DAZ[at["spine"]] == "abdomen" and "left_toe" not in at


def test_it_gives_indices_consistent_with_names():
    take = take_with(MIXAMO)
    at = motionlib.canonical_indices(take)
    joints = motionlib.canonical_joints(take)
    assert {MIXAMO[j]: part for part, j in at.items()} == joints


def test_it_refuses_a_skeleton_it_cannot_map_naming_the_missing_parts():
    with pytest.raises(CaptureError, match=r"no joint found for .*left_knee.*joints are "
                                           r"pelvis, thigh_l"):
        motionlib.canonical_indices(take_with(["pelvis", "thigh_l", "calf_l"]))


@pytest.mark.parametrize("parents", [[1, -1], [-1, 0, 0, 1]])
def test_it_refuses_joints_out_of_depth_first_order(parents):
    n = len(parents)
    with pytest.raises(ValueError, match="depth-first"):
        Skeleton(names=[f"j{i}" for i in range(n)], parents=parents, offsets=np.zeros((n, 3)),
                 channels=[()] * n, rotation_orders=[""] * n)


def test_it_finds_joints_by_name_and_lists_children(bvh_13_29):
    sk = motionlib.read(bvh_13_29).skeleton
    spine1 = sk.index("Spine1")
    assert [sk.names[c] for c in sk.children(spine1)] == ["Neck", "LeftShoulder",
                                                          "RightShoulder"]
    with pytest.raises(KeyError, match="Tail"):
        sk.index("Tail")
