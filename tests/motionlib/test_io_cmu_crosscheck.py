"""13_29.bvh (cgspeed) and 13_29.amc + 13.asf are the same take: BVH line k is AMC frame k."""

import numpy as np
import pytest

import motionlib


@pytest.mark.slow
def test_it_reads_the_bvh_and_the_amc_as_the_same_take(bvh_13_29, amc_13_29):
    bvh = motionlib.read(bvh_13_29)
    amc = motionlib.read(amc_13_29[0], asf=amc_13_29[1])
    assert bvh.n_frames == amc.n_frames + 1
    assert bvh.rest_pose_frame == 0
    p_bvh = motionlib.forward_kinematics(bvh)[1:]
    p_amc = motionlib.forward_kinematics(amc)
    at_bvh, at_amc = motionlib.canonical_indices(bvh), motionlib.canonical_indices(amc)
    assert set(at_bvh) == set(at_amc) == set(motionlib.CANONICAL_PARTS)
    tolerance = 1e-3 * motionlib.skeleton_height(bvh)
    for part in at_bvh:
        distance = np.linalg.norm(p_bvh[:, at_bvh[part]] - p_amc[:, at_amc[part]], axis=-1)
        assert distance.max() < tolerance, part
