"""Reading CMU ASF/AMC, and converting it to BVH with the same joint positions."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

import motionlib
from motionlib.io.asf_amc import read_asf

from .test_io_errors import ASF

TWO_BONES = ASF.replace(""":hierarchy
  begin
    root lowerback
  end""", """  begin
     id 2
     name upperback
     direction 1 0 0
     length 3
     axis 0 0 90 XYZ
    dof rx rz
  end
:hierarchy
  begin
    root lowerback
    lowerback upperback
  end""")
FRAMES = "".join(f"{n}\nroot 1 2 3 10 20 30\nlowerback 5 -10 15\nupperback {n * 7} -20\n"
                 for n in range(1, 6))


def write(tmp_path, asf_text=TWO_BONES, frames=FRAMES):
    (tmp_path / "s.asf").write_text(asf_text)
    (tmp_path / "m.amc").write_text(":FULLY-SPECIFIED\n:DEGREES\n" + frames)
    return tmp_path / "m.amc", tmp_path / "s.asf"


def test_it_builds_one_joint_per_bone_at_the_bone_start(tmp_path):
    take = motionlib.read(*write(tmp_path)[:1], asf=write(tmp_path)[1])
    sk = take.skeleton
    assert sk.names == ["root", "lowerback", "upperback"]
    assert list(sk.parents) == [-1, 0, 1]
    # lowerback starts at the root; upperback where lowerback ends (direction * length).
    assert_array_equal(sk.offsets, [[0, 0, 0], [0, 0, 0], [0, 2, 0]])
    assert_array_equal(sk.end_sites[2], [3, 0, 0])
    assert sk.channels[2] == ("Xrotation", "Zrotation")
    assert (take.format, take.fps, take.n_frames, take.rest_pose_frame) == ("amc", 120.0, 5, None)


def test_it_puts_channels_in_joint_order_as_degrees(tmp_path):
    path, asf = write(tmp_path)
    take = motionlib.read(path, asf=asf)
    assert_array_equal(take.channels[2], [1, 2, 3, 10, 20, 30, 5, -10, 15, 21, -20])


def test_it_rotates_about_the_asf_axis_frame(tmp_path):
    # upperback's axis turns X onto Y: its rx then turns about the world Y axis.
    frames = "1\nroot 0 0 0 0 0 0\nlowerback 0 0 0\nupperback 90 0\n"
    path, asf = write(tmp_path, frames=frames)
    take = motionlib.read(path, asf=asf)
    C = take.skeleton.axes[2]
    assert_allclose(C @ [1, 0, 0], [0, 1, 0], atol=1e-12)
    end = motionlib.kinematics.rest_positions(take)[-1]
    assert_allclose(end, [3, 2, 0], atol=1e-12)
    local = C @ np.array([[1, 0, 0], [0, 0, -1], [0, 1, 0]]) @ C.T  # C Rx(90) C^T
    assert_allclose(local @ [3, 0, 0], [0, 0, -3], atol=1e-12)


def test_it_converts_radians_to_degrees(tmp_path):
    rad = TWO_BONES.replace("angle deg", "angle rad").replace("axis 0 0 90 XYZ",
                                                              f"axis 0 0 {math.pi / 2} XYZ")
    frames = "1\nroot 0 0 0 0 0 0\nlowerback 0 0 0\nupperback 0 1.5707963267948966\n"
    path, asf = write(tmp_path, rad, frames)
    take = motionlib.read(path, asf=asf)
    assert take.channels[0, -1] == pytest.approx(90.0)
    assert_allclose(take.skeleton.axes[2] @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_it_reads_bones_listed_in_any_order_per_frame(tmp_path):
    shuffled = FRAMES.replace("lowerback 5 -10 15\nupperback 14 -20\n",
                              "upperback 14 -20\nlowerback 5 -10 15\n")
    assert shuffled != FRAMES
    a = motionlib.read(*write(tmp_path)[:1], asf=tmp_path / "s.asf")
    (tmp_path / "b").mkdir()
    b_path, b_asf = write(tmp_path / "b", frames=shuffled)
    b = motionlib.read(b_path, asf=b_asf)
    assert_array_equal(a.channels, b.channels)


def test_it_writes_an_amc_take_as_bvh_with_the_same_positions(tmp_path):
    path, asf = write(tmp_path)
    take = motionlib.read(path, asf=asf)
    motionlib.write_bvh(take, tmp_path / "m.bvh")
    bvh = motionlib.read(tmp_path / "m.bvh")
    assert bvh.skeleton.names == take.skeleton.names
    assert_allclose(motionlib.forward_kinematics(bvh), motionlib.forward_kinematics(take),
                    atol=1e-5)


@pytest.mark.slow
def test_it_converts_a_real_amc_to_bvh_with_the_same_positions(amc_13_29, tmp_path):
    take = motionlib.read(amc_13_29[0], asf=amc_13_29[1])
    motionlib.write_bvh(take, tmp_path / "13_29.bvh")
    bvh = motionlib.read(tmp_path / "13_29.bvh")
    assert bvh.n_frames == take.n_frames
    tolerance = 1e-5 * motionlib.skeleton_height(take)
    assert np.abs(motionlib.forward_kinematics(bvh) - motionlib.forward_kinematics(take)).max() \
        < tolerance


def test_it_reads_the_real_cmu_skeleton(amc_13_29):
    asf = read_asf(amc_13_29[1])
    sk = asf.skeleton
    assert sk.n_joints == 31 and sk.names[0] == "root"
    assert sk.channels[0] == ("Xposition", "Yposition", "Zposition",
                              "Xrotation", "Yrotation", "Zrotation")
    assert sk.channels[sk.index("lhipjoint")] == ()
    assert sk.n_channels == 62


@pytest.mark.slow
def test_it_reads_every_cmu_motion_beside_the_repository(amc_13_29):
    cmu = amc_13_29[0].parents[1]
    for motion in sorted((cmu / "amc").glob("*.amc")):
        subject = motion.stem.split("_")[0]
        take = motionlib.read(motion, asf=cmu / "asf" / f"{subject}.asf")
        assert take.n_frames > 500 and np.all(np.isfinite(take.channels))
        assert set(motionlib.canonical_indices(take)) == set(motionlib.CANONICAL_PARTS)


def test_its_compiled_reader_gives_what_the_line_by_line_reader_gives(amc_13_29):
    from motionlib.io.asf_amc import _amc_body, _amc_fast, _amc_lines

    amc, asf_path = amc_13_29
    asf = read_asf(asf_path)
    data = amc.read_bytes()
    offset, first_line = _amc_body(data, amc)
    fast = _amc_fast(data, offset, asf.skeleton)
    slow = _amc_lines(data[offset:].decode(), first_line, asf, amc)
    assert fast is not None and fast.shape == (4592, asf.skeleton.n_channels)
    assert_array_equal(fast, slow)


def test_its_compiled_reader_declines_a_frame_that_departs_from_the_first(tmp_path):
    from motionlib.io.asf_amc import _amc_body, _amc_fast

    shuffled = FRAMES.replace("lowerback 5 -10 15\nupperback 14 -20\n",
                              "upperback 14 -20\nlowerback 5 -10 15\n", 1)
    amc, asf = write(tmp_path, frames=shuffled)
    data = amc.read_bytes()
    assert _amc_fast(data, _amc_body(data, amc)[0], read_asf(asf).skeleton) is None


@settings(derandomize=True, max_examples=300, deadline=None)
@given(st.lists(st.sampled_from(["6\n", "7\n", "root 1 2 3 10 20 30\n", "lowerback 5 -10 15\n",
                                 "upperback 1 2\n", "6", "root", "upperback", "5", "-10.5", "1e3",
                                 "nan", "x", "#", " ", "\n", "\t", "\r\n"]), max_size=40))
def test_its_compiled_reader_agrees_with_the_line_by_line_reader_or_declines(tmp_path_factory,
                                                                              pieces):
    from motionlib.io.asf_amc import _amc_body, _amc_fast, _amc_lines

    amc, asf_path = write(tmp_path_factory.mktemp("amc"), frames=FRAMES + "".join(pieces))
    asf = read_asf(asf_path)
    data = amc.read_bytes()
    offset, first_line = _amc_body(data, amc)
    fast = _amc_fast(data, offset, asf.skeleton)
    if fast is not None:  # what it accepts, the careful reader reads the same
        assert_array_equal(fast, _amc_lines(data[offset:].decode(), first_line, asf, amc))


def test_its_compiled_reader_declines_a_frame_written_on_one_line(tmp_path):
    from motionlib.io.asf_amc import _amc_body, _amc_fast

    one_line = FRAMES + "6 root 1 2 3 10 20 30 lowerback 5 -10 15 upperback 1 2\n"
    amc, asf = write(tmp_path, frames=one_line)
    data = amc.read_bytes()
    assert _amc_fast(data, _amc_body(data, amc)[0], read_asf(asf).skeleton) is None
    with pytest.raises(motionlib.CaptureError):
        motionlib.read(amc, asf=asf)
