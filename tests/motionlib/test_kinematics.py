"""Forward kinematics: the vectorised version against a slow, obvious per-frame oracle."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

import motionlib
from motionlib import features
from motionlib.kinematics import body_frame_rows, euler_to_matrix, matrix_to_euler_zyx
from motionlib.skeleton import Skeleton
from motionlib.take import Take


def rot(axis: str, degrees: float) -> np.ndarray:
    c, s = np.cos(np.radians(degrees)), np.sin(np.radians(degrees))
    return {"X": np.array([[1, 0, 0], [0, c, -s], [0, s, c]]),
            "Y": np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]]),
            "Z": np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])}[axis]


def oracle(take: Take) -> np.ndarray:
    """One frame at a time, one joint at a time, matrices written out."""
    sk = take.skeleton
    out = np.zeros((take.n_frames, sk.n_joints, 3))
    for f in range(take.n_frames):
        glob, col = {}, 0
        for j in range(sk.n_joints):
            local_t = sk.offsets[j].astype(float).copy()
            values = {}
            for name in sk.channels[j]:
                values[name] = take.channels[f, col]
                col += 1
            for a, axis in enumerate("XYZ"):
                if f"{axis}position" in values:
                    local_t[a] = values[f"{axis}position"]
            local_r = np.eye(3)
            for axis in sk.rotation_orders[j]:
                local_r = local_r @ rot(axis, values.get(f"{axis}rotation", 0.0))
            if sk.axes is not None:
                local_r = sk.axes[j] @ local_r @ np.linalg.inv(sk.axes[j])
            p = sk.parents[j]
            if p < 0:
                out[f, j], glob[j] = local_t, local_r
            else:
                out[f, j] = out[f, p] + glob[p] @ local_t
                glob[j] = glob[p] @ local_r
    return out


def random_take(rng, n_frames=7, n_joints=9, with_axes=False) -> Take:
    parents, chain = [-1], [0]  # depth-first: attach to the previous joint or an ancestor
    for j in range(1, n_joints):
        del chain[int(rng.integers(1, len(chain) + 1)):]
        parents.append(chain[-1])
        chain.append(j)
    channels, orders = [], []
    for j in range(n_joints):
        rots = [f"{a}rotation" for a in rng.permutation(list("XYZ"))[:rng.integers(1, 4)]]
        pos = [f"{a}position" for a in "XYZ" if j == 0 or rng.random() < 0.2]
        chans = list(rng.permutation(rots + pos))
        channels.append(tuple(chans))
        orders.append("".join(c[0] for c in chans if c.endswith("rotation")))
    axes = None
    if with_axes:
        axes = euler_to_matrix(rng.uniform(-180, 180, (n_joints, 3)), "ZYX")
    sk = Skeleton(names=[f"j{j}" for j in range(n_joints)], parents=parents,
                  offsets=rng.normal(size=(n_joints, 3)), channels=channels,
                  rotation_orders=orders, axes=axes)
    values = rng.uniform(-180, 180, (n_frames, sk.n_channels))
    return Take(name="random", format="bvh", fps=30.0, frame_time=1 / 30, channels=values,
                skeleton=sk)


@pytest.mark.parametrize("seed", range(6))
def test_it_agrees_with_the_per_frame_oracle_on_random_rotations_and_channel_orders(seed):
    take = random_take(np.random.default_rng(seed))
    assert_allclose(motionlib.forward_kinematics(take), oracle(take), atol=1e-9)


@pytest.mark.parametrize("seed", range(3))
def test_it_agrees_with_the_oracle_with_asf_axis_frames(seed):
    take = random_take(np.random.default_rng(100 + seed), with_axes=True)
    assert_allclose(motionlib.forward_kinematics(take), oracle(take), atol=1e-9)


@pytest.mark.parametrize("with_axes", [False, True])
def test_it_agrees_with_the_oracle_when_some_angles_are_exactly_zero(with_axes):
    # Zero angles are skipped and a joint that does not turn shares its parent's rotation.
    rng = np.random.default_rng(7)
    take = random_take(rng, n_frames=40, n_joints=12, with_axes=with_axes)
    take.channels[rng.random(take.channels.shape) < 0.4] = 0.0
    take.channels[::3, :] = 0.0  # whole frames at rest too
    assert_allclose(motionlib.forward_kinematics(take), oracle(take), atol=1e-9)


def test_it_agrees_with_the_oracle_on_a_real_take(bvh_13_29):
    take = motionlib.read(bvh_13_29).slice(0, 60)  # frame 0 is all zeros but the root
    assert_allclose(motionlib.forward_kinematics(take), oracle(take), atol=1e-9)


def chain(channel_values, offsets=((0, 0, 0), (1, 0, 0), (1, 0, 0))):
    sk = Skeleton(names=["root", "a", "b"], parents=[-1, 0, 1], offsets=offsets,
                  channels=[("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation",
                             "Xrotation"), ("Zrotation", "Yrotation", "Xrotation"), ()],
                  rotation_orders=["ZYX", "ZYX", ""])
    return Take(name="chain", format="bvh", fps=1.0, frame_time=1.0,
                channels=np.atleast_2d(np.asarray(channel_values, float)), skeleton=sk)


def test_it_places_joints_at_their_offsets_when_every_angle_is_zero():
    positions = motionlib.forward_kinematics(chain([1, 2, 3, 0, 0, 0, 0, 0, 0]))
    assert_allclose(positions[0], [[1, 2, 3], [2, 2, 3], [3, 2, 3]])


def test_it_turns_a_child_by_its_parents_rotation():
    # Root turned 90 degrees about Z: +X becomes +Y; joint a bends another 90: +Y becomes -X.
    positions = motionlib.forward_kinematics(chain([0, 0, 0, 90, 0, 0, 90, 0, 0]))
    assert_allclose(positions[0], [[0, 0, 0], [0, 1, 0], [-1, 1, 0]], atol=1e-12)


def test_it_composes_rotation_channels_in_the_order_they_are_listed():
    # Z then Y (R = Rz @ Ry) differs from Y then Z; the joint after the rotation shows which.
    positions = motionlib.forward_kinematics(chain([0, 0, 0, 90, 90, 0, 0, 0, 0]))
    expected = rot("Z", 90) @ rot("Y", 90) @ np.array([1.0, 0, 0])
    assert_allclose(positions[0, 1], expected, atol=1e-12)


def test_it_keeps_bone_lengths_in_every_frame_of_a_real_take(bvh_13_29):
    take = motionlib.read(bvh_13_29)
    positions = motionlib.forward_kinematics(take)
    for j, p in enumerate(take.skeleton.parents):
        if p >= 0:
            length = np.linalg.norm(positions[:, j] - positions[:, p], axis=-1)
            assert_allclose(length, np.linalg.norm(take.skeleton.offsets[j]), atol=1e-9)


def test_it_returns_float64_positions_of_shape_frames_joints_3(bvh_13_29):
    take = motionlib.read(bvh_13_29)
    positions = motionlib.forward_kinematics(take)
    assert positions.shape == (4593, 31, 3) and positions.dtype == np.float64


def test_it_recovers_zyx_euler_angles_from_matrices():
    rng = np.random.default_rng(0)
    angles = np.column_stack([rng.uniform(-180, 180, 500), rng.uniform(-89, 89, 500),
                              rng.uniform(-180, 180, 500)])
    R = euler_to_matrix(angles, "ZYX")
    assert_allclose(matrix_to_euler_zyx(R), angles, atol=1e-9)


def test_it_reproduces_the_matrix_at_gimbal_lock():
    angles = np.array([[30.0, 90.0, 20.0], [-50.0, -90.0, 45.0]])
    R = euler_to_matrix(angles, "ZYX")
    assert_allclose(euler_to_matrix(matrix_to_euler_zyx(R), "ZYX"), R, atol=1e-9)


def test_it_measures_skeleton_height_of_a_take_and_of_positions():
    take = chain([0, 0, 0, 0, 0, 0, 0, 0, 0], offsets=((0, 0, 0), (0, 1, 0), (0, 2, 0)))
    assert motionlib.skeleton_height(take) == pytest.approx(3.0)
    positions = motionlib.forward_kinematics(take)
    assert motionlib.skeleton_height(positions) == pytest.approx(3.0)
    with pytest.raises(ValueError, match="shape"):
        motionlib.skeleton_height(np.zeros((4, 3)))


def test_it_reproduces_matrices_close_to_gimbal_lock():
    angles = np.array([[30.0, 90.0 - 1e-7, 20.0], [-50.0, -90.0 + 1e-9, 45.0],
                       [10.0, 89.9999, -170.0]])
    R = euler_to_matrix(angles, "ZYX")
    assert_allclose(euler_to_matrix(matrix_to_euler_zyx(R), "ZYX"), R, atol=1e-9)


def test_it_moves_every_joint_with_the_root_translation(bvh_13_29):
    take = motionlib.read(bvh_13_29).slice(1, 200)
    positions = motionlib.forward_kinematics(take)
    shifted = take.channels.copy()
    shifted[:, :3] += [10.0, -2.0, 3.5]  # Xposition Yposition Zposition of the root
    moved = motionlib.forward_kinematics(take, shifted)
    assert_allclose(moved - positions, np.broadcast_to([10.0, -2.0, 3.5], positions.shape),
                    atol=1e-9)


def test_it_turns_every_joint_about_the_root_with_the_outermost_root_rotation(bvh_13_29):
    # The root's channels are Zrotation Yrotation Xrotation, R = Rz @ Ry @ Rx: adding an angle
    # to Z turns the whole body about the world Z axis through the root.
    take = motionlib.read(bvh_13_29).slice(1, 200)
    assert take.skeleton.channels[0][3] == "Zrotation"
    positions = motionlib.forward_kinematics(take)
    turned = take.channels.copy()
    turned[:, 3] += 90.0
    rotated = motionlib.forward_kinematics(take, turned)
    root = positions[:, :1]
    assert_allclose(rotated, root + (positions - root) @ rot("Z", 90).T, atol=1e-9)


def test_it_turns_by_any_angle_to_a_few_ulp():
    # One frame per angle: joint a turned about Z puts the child at (cos, sin, 0).
    rng = np.random.default_rng(3)
    degrees = np.concatenate([rng.uniform(-720, 720, 20000), np.arange(-720, 720.01, 0.05),
                              [90.0, -180.0, 719.99, 1e-9, -0.04999999, 0.5, -0.5, 359.5],
                              rng.uniform(-1e6, 1e6, 200), [1e14 + 0.25, -3e15, 1e300]])
    values = np.zeros((degrees.size, 9))
    values[:, 6] = degrees
    positions = motionlib.forward_kinematics(chain(values))
    radians = np.deg2rad(np.fmod(degrees, 360))  # exact: large angles stay accurate
    assert_allclose(positions[:, 2, 0] - 1, np.cos(radians), rtol=0, atol=4e-15)
    assert_allclose(positions[:, 2, 1], np.sin(radians), rtol=0, atol=4e-15)


def test_it_gives_nan_positions_for_nan_angles_rather_than_failing():
    positions = motionlib.forward_kinematics(chain([0, 0, 0, 0, 0, 0, np.nan, 0, 0]))
    assert np.isnan(positions[0, 2]).all() and not np.isnan(positions[0, :2]).any()


def test_it_refuses_channels_of_the_wrong_shape():
    take = chain([0] * 9)
    with pytest.raises(ValueError, match=r"shape \(n_frames, 9\)"):
        motionlib.forward_kinematics(take, np.zeros((3, 8)))


def test_it_handles_a_take_without_frames():
    take = chain(np.zeros((0, 9)))
    assert motionlib.forward_kinematics(take).shape == (0, 3, 3)


def _body_frame_oracle(take, chosen, root, left_hip, right_hip, first=0):
    positions = motionlib.forward_kinematics(take)[first:]
    body = features.body_frame_positions(positions, {"root": root, "left_hip": left_hip,
                                                     "right_hip": right_hip}, chosen)
    return np.concatenate([body.reshape(len(positions), -1), positions[:, root, 1:2]], axis=1)


@pytest.mark.parametrize("with_axes", [False, True])
def test_body_frame_rows_are_the_body_frame_positions_of_the_kinematics(with_axes):
    """The same values (not merely close): the same operations in the same order."""
    take = random_take(np.random.default_rng(11), n_frames=40, with_axes=with_axes)
    chosen = [8, 3, 0, 5]
    rows = body_frame_rows(take, chosen, root=0, left_hip=1, right_hip=2, first=3)
    np.testing.assert_array_equal(rows, _body_frame_oracle(take, chosen, 0, 1, 2, first=3))


def test_body_frame_rows_of_a_real_take(amc_13_29):
    take = motionlib.read(amc_13_29[0], asf=amc_13_29[1])
    at = motionlib.canonical_indices(take)
    chosen = [at[j] for j in ("head", "left_wrist", "right_ankle")]
    rows = body_frame_rows(take, chosen, root=at["root"], left_hip=at["left_hip"],
                           right_hip=at["right_hip"])
    expected = _body_frame_oracle(take, chosen, at["root"], at["left_hip"], at["right_hip"])
    np.testing.assert_array_equal(rows, expected)


def test_body_frame_rows_refuse_a_joint_that_is_not_in_the_skeleton():
    take = random_take(np.random.default_rng(12))
    with pytest.raises(ValueError, match="joint index out of range"):
        body_frame_rows(take, [0, 99], root=0, left_hip=1, right_hip=2)
