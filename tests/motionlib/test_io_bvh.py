"""Reading and writing BVH."""

import io

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

import motionlib
from motionlib import CaptureError, synth

SMALL = """HIERARCHY
ROOT Hips
{
\tOFFSET 0 0 0
\tCHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
\tJOINT Chest
\t{
\t\tOFFSET 0 5.5 0
\t\tCHANNELS 3 Yrotation Xrotation Zrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 2 0
\t\t}
\t}
\tJOINT Leg
\t{
\t\tOFFSET 1 -1 0
\t\tCHANNELS 2 Xrotation Zrotation
\t\tEnd Site
\t\t{
\t\t\tOFFSET 0 -4 0
\t\t}
\t}
}
MOTION
Frames: 3
Frame Time: 0.04
1 2 3 10 20 30 1 2 3 4 5
-1.5 2.25 3 0 0 0 0 0 0 0 0
1e1 2E-1 -3.5e+0 90 0 0 0 0 0 0 0
"""


def write(tmp_path, text, name="take.bvh", newline="\n"):
    path = tmp_path / name
    path.write_bytes(text.replace("\n", newline).encode())
    return path


def test_it_reads_joints_channels_and_end_sites(tmp_path):
    take = motionlib.read(write(tmp_path, SMALL))
    sk = take.skeleton
    assert sk.names == ["Hips", "Chest", "Leg"]
    assert list(sk.parents) == [-1, 0, 0]
    assert_array_equal(sk.offsets, [[0, 0, 0], [0, 5.5, 0], [1, -1, 0]])
    assert sk.channels[1] == ("Yrotation", "Xrotation", "Zrotation")
    assert sk.rotation_orders == ["ZXY", "YXZ", "XZ"]
    assert_array_equal(sk.end_sites[2], [0, -4, 0])
    assert (take.format, take.name, take.n_frames, take.fps) == ("bvh", "take", 3, 25.0)
    assert take.frame_time == 0.04 and take.duration == pytest.approx(0.12)


def test_it_reads_scientific_notation_and_signs(tmp_path):
    take = motionlib.read(write(tmp_path, SMALL))
    assert_array_equal(take.channels[1, :3], [-1.5, 2.25, 3])
    assert_array_equal(take.channels[2, :3], [10.0, 0.2, -3.5])


def test_it_reads_crlf_and_tabs_and_blank_lines_alike(tmp_path):
    plain = motionlib.read(write(tmp_path, SMALL))
    crlf = motionlib.read(write(tmp_path, SMALL.replace(" ", "\t"), "crlf.bvh", "\r\n"))
    spaced = motionlib.read(write(tmp_path, SMALL.replace("Frame Time: 0.04\n",
                                                          "Frame Time: 0.04\n\n  \n"), "b.bvh"))
    assert_array_equal(plain.channels, crlf.channels)
    assert_array_equal(plain.channels, spaced.channels)
    assert crlf.skeleton.names == plain.skeleton.names


def test_it_refuses_a_take_with_no_frames_naming_the_line(tmp_path):
    text = SMALL.split("Frames:")[0] + "Frames: 0\nFrame Time: 0.01\n"
    line = text.count("\n") - 1
    with pytest.raises(CaptureError, match=rf"\.bvh:{line}: the take has 0 frames; a capture "
                                           r"needs at least 1$"):
        motionlib.read(write(tmp_path, text))


def test_it_reads_a_take_of_one_frame(tmp_path):
    text = SMALL.split("Frames:")[0] + "Frames: 1\nFrame Time: 0.01\n" + " ".join(["0"] * 11) + "\n"
    assert motionlib.read(write(tmp_path, text)).channels.shape == (1, 11)


def test_it_parses_plain_decimals_exactly_like_float(tmp_path):
    rng = np.random.default_rng(0)
    values = np.round(rng.uniform(-400, 400, (50, 11)), rng.integers(0, 7))
    body = "\n".join(" ".join(repr(float(v)) for v in row) for row in values)
    text = SMALL.split("Frames:")[0] + f"Frames: 50\nFrame Time: 0.01\n{body}\n"
    take = motionlib.read(write(tmp_path, text))
    assert_array_equal(take.channels, values)


def test_it_detects_the_added_t_pose_of_a_cgspeed_file(bvh_13_29):
    take = motionlib.read(bvh_13_29)
    assert take.rest_pose_frame == 0
    assert take.n_frames == 4593 and take.skeleton.n_joints == 31 and take.fps == 120.0


def test_it_does_not_invent_a_rest_pose(tmp_path):
    assert motionlib.read(write(tmp_path, SMALL)).rest_pose_frame is None
    take, _ = synth.generate(seed=0, n_segments=2)
    path = tmp_path / "synth.bvh"
    motionlib.write_bvh(take, path)
    assert motionlib.read(path).rest_pose_frame is None


def test_it_detects_a_whole_degree_mostly_zero_first_frame(tmp_path):
    body = "0 17 0 0 0 0 0 0 0 21 0\n0.1 17 0 3.2 -1.5 0.7 1.1 2.3 4.1 -2.2 9.9\n"
    text = SMALL.split("Frames:")[0] + f"Frames: 2\nFrame Time: 0.01\n{body}"
    assert motionlib.read(write(tmp_path, text)).rest_pose_frame == 0


def test_it_round_trips_through_write_bvh(bvh_13_29, tmp_path):
    take = motionlib.read(bvh_13_29)
    motionlib.write_bvh(take, tmp_path / "copy.bvh")
    again = motionlib.read(tmp_path / "copy.bvh")
    assert again.skeleton.names == take.skeleton.names
    assert again.skeleton.channels == take.skeleton.channels
    assert_array_equal(again.skeleton.offsets, take.skeleton.offsets)
    assert again.frame_time == take.frame_time
    assert_array_equal(again.channels, take.channels)


def test_it_writes_a_trimmed_copy_with_the_same_frames(bvh_13_29, tmp_path):
    take = motionlib.read(bvh_13_29)
    buffer = io.StringIO()
    motionlib.write_bvh(take, buffer, start=100, stop=250)
    path = tmp_path / "clip.bvh"
    path.write_text(buffer.getvalue())
    clip = motionlib.read(path)
    assert clip.n_frames == 150 and clip.rest_pose_frame is None
    assert_array_equal(clip.channels, take.channels[100:250])
    assert_allclose(motionlib.forward_kinematics(clip),
                    motionlib.forward_kinematics(take)[100:250], atol=1e-9)


def test_it_round_trips_a_synthetic_take_to_six_decimals(tmp_path):
    take, _ = synth.generate(seed=2, n_segments=2)
    motionlib.write_bvh(take, tmp_path / "s.bvh")
    again = motionlib.read(tmp_path / "s.bvh")
    assert again.fps == take.fps
    assert_allclose(again.channels, take.channels, atol=5e-7)


def test_it_refuses_a_frame_range_outside_the_take(tmp_path):
    take = motionlib.read(write(tmp_path, SMALL))
    with pytest.raises(ValueError, match=r"\[2, 9\)"):
        motionlib.write_bvh(take, tmp_path / "x.bvh", start=2, stop=9)


def test_it_slices_a_take_keeping_the_rest_pose_only_when_inside(bvh_13_29):
    take = motionlib.read(bvh_13_29)
    assert take.slice(0, 10).rest_pose_frame == 0
    part = take.slice(1, 11)
    assert part.rest_pose_frame is None and part.n_frames == 10
    assert_array_equal(part.channels, take.channels[1:11])


@pytest.mark.parametrize("seed", range(4))
def test_it_round_trips_random_skeletons_and_channel_orders(tmp_path, seed):
    from .test_kinematics import random_take

    take = random_take(np.random.default_rng(seed), n_frames=12, n_joints=8)
    take.skeleton.end_sites[take.skeleton.n_joints - 1] = np.array([0.5, -1.25, 2.0])
    path = tmp_path / "random.bvh"
    motionlib.write_bvh(take, path)
    again = motionlib.read(path)
    assert again.skeleton.channels == take.skeleton.channels
    assert list(again.skeleton.parents) == list(take.skeleton.parents)
    assert_allclose(again.skeleton.offsets, take.skeleton.offsets, atol=5e-7)
    assert_allclose(again.channels, take.channels, atol=5e-7)
    assert_allclose(motionlib.forward_kinematics(again), motionlib.forward_kinematics(take),
                    atol=1e-4)
