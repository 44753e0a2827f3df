"""Physical values out of range, malformed ASF/AMC structure, odd line ends and huge names:
each a CaptureError naming file, line and a shortened value (issue 11, items 11 and 12)."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

import motionlib
from motionlib import CaptureError
from tests.motionlib.test_io_errors import AMC_FRAME, ASF, FRAME, HEADER


def write(tmp_path, text, name="bad.bvh"):
    path = tmp_path / name
    path.write_text(text, newline="")
    return path


def amc_pair(tmp_path, frames, asf=ASF):
    return write(tmp_path, frames, "bad.amc"), write(tmp_path, asf, "bad.asf")


def test_it_refuses_a_frame_time_that_makes_an_absurd_frame_rate(tmp_path):
    text = HEADER + "Frames: 1\nFrame Time: 1e-300\n" + FRAME
    with pytest.raises(CaptureError, match=r"bad\.bvh:18: frame time '1e-300' is outside "
                                           r"0\.0001 to 10 seconds"):
        motionlib.read(write(tmp_path, text))


def test_it_refuses_an_offset_beyond_the_length_limit(tmp_path):
    text = HEADER.replace("OFFSET 0 1 0\n    CHANNELS", "OFFSET 0 1e300 0\n    CHANNELS")
    with pytest.raises(CaptureError, match=r"bad\.bvh:8: OFFSET of Head is '1e300', beyond the "
                                           r"limit of ±1e\+06"):
        motionlib.read(write(tmp_path, text + "Frames: 1\nFrame Time: 0.01\n" + FRAME))


def test_it_refuses_a_position_channel_beyond_the_length_limit(tmp_path):
    text = HEADER + "Frames: 2\nFrame Time: 0.01\n" + FRAME + "0 2e7 2 3 4 5 6 7 8\n"
    with pytest.raises(CaptureError, match=r"bad\.bvh:20: frame 1, value 2: '2e7' is a "
                                           r"position beyond the limit of ±1e\+06"):
        motionlib.read(write(tmp_path, text))


def test_it_refuses_an_amc_root_position_beyond_the_length_limit(tmp_path):
    frames = AMC_FRAME.format(n=1) + "2\nroot 0 1e300 0 0 0 0\nlowerback 1 2 3\n"
    amc, asf = amc_pair(tmp_path, frames)
    with pytest.raises(CaptureError, match=r"bad\.amc:5: value '1e300' of bone 'root' is a "
                                           r"position beyond the limit"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_an_asf_bone_length_beyond_the_length_limit(tmp_path):
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1), ASF.replace("length 2", "length 1e300"))
    with pytest.raises(CaptureError, match=r"bad\.asf:17: length of lowerback is '1e300', "
                                           r"beyond the limit"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_an_asf_that_names_root_as_a_child(tmp_path):
    asf = ASF.replace("    root lowerback\n", "    root lowerback\n    lowerback root\n")
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1), asf)
    with pytest.raises(CaptureError, match=r"bad\.asf:24: 'root' is listed as a child of "
                                           r"'lowerback'; the root has no parent"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_an_asf_of_comments_only(tmp_path):
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1), "# a skeleton\n# nothing else\n")
    with pytest.raises(CaptureError, match=r"bad\.asf:3: no ASF sections \(:root, :bonedata, "
                                           r":hierarchy\), only comments"):
        motionlib.read(amc, asf=asf)


def test_it_names_the_hierarchy_line_of_a_bone_listed_twice(tmp_path):
    asf = ASF.replace("    root lowerback\n", "    root lowerback lowerback\n")
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1), asf)
    with pytest.raises(CaptureError, match=r"bad\.asf:23: bone 'lowerback' appears twice"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_an_amc_frame_that_lists_no_bones(tmp_path):
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1) + "2\n" + AMC_FRAME.format(n=3))
    with pytest.raises(CaptureError, match=r"bad\.amc:4: frame 2 lists no bones"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_a_last_amc_frame_that_lists_no_bones(tmp_path):
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1) + "2\n")
    with pytest.raises(CaptureError, match=r"bad\.amc:4: frame 2 lists no bones"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_an_amc_cut_off_part_way_through_its_last_frame(tmp_path):
    # An interrupted copy or upload: the last frame's other bones would read as zeros.
    frames = AMC_FRAME.format(n=1) + AMC_FRAME.format(n=2) + "3\nroot 0 0 0 0 0 0\n"
    amc, asf = amc_pair(tmp_path, frames)
    with pytest.raises(CaptureError, match=r"bad\.amc:7: frame 3 lacks bone 'lowerback' "
                                           r"that frame 1 lists: a cut-off or damaged file"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_an_amc_frame_that_lists_other_bones_than_the_first(tmp_path):
    frames = ("1\nroot 0 0 0 0 0 0\n" + AMC_FRAME.format(n=2) + AMC_FRAME.format(n=3))
    amc, asf = amc_pair(tmp_path, frames)
    with pytest.raises(CaptureError, match=r"bad\.amc:3: frame 2 lists bone 'lowerback', "
                                           r"which frame 1 does not"):
        motionlib.read(amc, asf=asf)
    middle = AMC_FRAME.format(n=1) + "2\nroot 0 0 0 0 0 0\n" + AMC_FRAME.format(n=3)
    amc, asf = amc_pair(tmp_path, middle)
    with pytest.raises(CaptureError, match=r"bad\.amc:4: frame 2 lacks bone 'lowerback'"):
        motionlib.read(amc, asf=asf)


def test_it_reads_a_bvh_with_cr_only_line_ends_like_lf(tmp_path):
    text = HEADER + "Frames: 2\nFrame Time: 0.01\n" + FRAME * 2
    lf = motionlib.read(write(tmp_path, text, "lf.bvh"))
    cr = motionlib.read(write(tmp_path, text.replace("\n", "\r"), "cr.bvh"))
    assert_array_equal(cr.channels, lf.channels)
    assert cr.skeleton.names == lf.skeleton.names


def test_it_names_the_right_line_in_a_bvh_with_cr_only_line_ends(tmp_path):
    text = HEADER + "Frames: 2\nFrame Time: 0.01\n" + FRAME + "0 1 2\n"
    with pytest.raises(CaptureError, match=r"bad\.bvh:20: frame 1: expected 9 values, found 3"):
        motionlib.read(write(tmp_path, text.replace("\n", "\r")))


def test_it_reads_asf_and_amc_with_cr_only_line_ends(tmp_path):
    frames = AMC_FRAME.format(n=1) + AMC_FRAME.format(n=2)
    lf = motionlib.read(*amc_pair(tmp_path, frames)[:1], asf=amc_pair(tmp_path, frames)[1])
    cr_dir = tmp_path / "cr"
    cr_dir.mkdir()
    amc, asf = amc_pair(cr_dir, frames.replace("\n", "\r"), ASF.replace("\n", "\r"))
    cr = motionlib.read(amc, asf=asf)
    assert_array_equal(cr.channels, lf.channels)


def test_it_does_not_echo_a_huge_joint_name(tmp_path):
    name = "J" * 1_000_000
    text = HEADER.replace("JOINT Head", f"JOINT {name}")
    with pytest.raises(CaptureError) as caught:
        motionlib.read(write(tmp_path, text + "Frames: 1\nFrame Time: 0.01\n" + FRAME))
    message = str(caught.value)
    assert "is longer than the limit of 200 characters" in message
    assert "(1000000 characters)" in message and len(message) < 300


def test_it_does_not_echo_a_huge_asf_bone_name(tmp_path):
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1),
                        ASF.replace("name lowerback", "name " + "b" * 1_000_000))
    with pytest.raises(CaptureError) as caught:
        motionlib.read(amc, asf=asf)
    assert "longer than the limit" in str(caught.value) and len(str(caught.value)) < 300


def test_it_does_not_echo_a_huge_unknown_token(tmp_path):
    text = HEADER.replace("CHANNELS 3 Zrotation", "CHANNELS 3 " + "W" * 1_000_000)
    with pytest.raises(CaptureError) as caught:
        motionlib.read(write(tmp_path, text + "Frames: 1\nFrame Time: 0.01\n" + FRAME))
    assert len(str(caught.value)) < 300


def test_it_caps_any_message_it_is_given():
    assert len(str(CaptureError("x" * 100_000, path="a.bvh", line=3))) < 1100


def test_an_empty_take_is_refused_with_the_frames_the_limits_ask_for(tmp_path):
    path = write(tmp_path, HEADER + "Frames: 0\nFrame Time: 0.01\n")
    with pytest.raises(CaptureError, match=r"bad\.bvh:17: the take has 0 frames; a capture "
                                           r"needs at least 1"):
        motionlib.read(path)
    with pytest.raises(CaptureError, match=r"bad\.bvh:17: the take has 0 frames; a capture "
                                           r"needs at least 2"):
        motionlib.read(path, limits=motionlib.take.Limits(min_frames=2))


def test_its_limits_leave_a_normal_take_alone(tmp_path):
    text = HEADER + "Frames: 3\nFrame Time: 0.0083333\n" + FRAME * 3
    take = motionlib.read(write(tmp_path, text))
    assert take.channels.shape == (3, 9) and np.isfinite(take.channels).all()


def test_it_does_not_echo_a_huge_number(tmp_path):
    text = HEADER + "Frames: 1\nFrame Time: 0.01\n" + FRAME.replace("8\n", "9" * 1_000_000 + "\n")
    with pytest.raises(CaptureError, match=r"bad\.bvh:19: frame 0, value 9: '9999.*\(1000000 "
                                           r"characters\) is not a finite number") as caught:
        motionlib.read(write(tmp_path, text))
    assert len(str(caught.value)) < 300


def test_it_does_not_echo_a_huge_asf_unit(tmp_path):
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1),
                        ASF.replace("angle deg", "angle " + "d" * 1_000_000))
    with pytest.raises(CaptureError, match=r"bad\.asf:6: angle unit must be deg or rad") as caught:
        motionlib.read(amc, asf=asf)
    assert len(str(caught.value)) < 300


def test_it_refuses_an_asf_bone_whose_direction_times_length_is_beyond_the_limit(tmp_path):
    asf = ASF.replace("direction 0 1 0", "direction 0 1000 0").replace("length 2", "length 1e4")
    amc, asf = amc_pair(tmp_path, AMC_FRAME.format(n=1), asf)
    with pytest.raises(CaptureError, match=r"bad\.asf:13: bone lowerback is 1e\+07 long "
                                           r"\(direction x length\), beyond the limit"):
        motionlib.read(amc, asf=asf)


def test_it_refuses_a_frame_count_of_a_hundred_digits_as_beyond_the_limit(tmp_path):
    text = HEADER + "Frames: " + "9" * 100 + "\nFrame Time: 0.01\n" + FRAME
    with pytest.raises(CaptureError, match=r"bad\.bvh:17: frame count '9999.* is more than the "
                                           r"limit of 2000000"):
        motionlib.read(write(tmp_path, text))
