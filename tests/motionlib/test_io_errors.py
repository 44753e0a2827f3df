"""Bad capture files give a CaptureError naming the file, the line and what was wrong."""

import pytest

import motionlib
from motionlib import CaptureError

HEADER = """HIERARCHY
ROOT Hips
{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation
  JOINT Head
  {
    OFFSET 0 1 0
    CHANNELS 3 Zrotation Yrotation Xrotation
    End Site
    {
      OFFSET 0 1 0
    }
  }
}
MOTION
"""  # MOTION is line 16; Frames 17; Frame Time 18; first frame line 19
FRAME = "0 1 2 3 4 5 6 7 8\n"

ASF = """:version 1.10
:name test
:units
  mass 1.0
  length 1.0
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name lowerback
     direction 0 1 0
     length 2
     axis 0 0 0 XYZ
    dof rx ry rz
  end
:hierarchy
  begin
    root lowerback
  end
"""
AMC_FRAME = "{n}\nroot 0 0 0 0 0 0\nlowerback 1 2 3\n"


def bvh(tmp_path, text):
    path = tmp_path / "bad.bvh"
    path.write_text(text)
    return path


def amc(tmp_path, frames_text):
    (tmp_path / "s.asf").write_text(ASF)
    path = tmp_path / "bad.amc"
    path.write_text(":FULLY-SPECIFIED\n:DEGREES\n" + frames_text)
    return path


def test_it_is_a_value_error():
    assert issubclass(CaptureError, ValueError)


def test_it_rejects_an_empty_file(tmp_path):
    with pytest.raises(CaptureError, match=r"bad\.bvh:1: empty file"):
        motionlib.read(bvh(tmp_path, "  \n\n"))


def test_it_rejects_a_truncated_motion_section(tmp_path):
    text = HEADER + "Frames: 3\nFrame Time: 0.01\n" + FRAME * 2
    with pytest.raises(CaptureError, match=r"bad\.bvh:20: truncated MOTION section: "
                                           r"'Frames: 3' but the file ends after 2 frame lines"):
        motionlib.read(bvh(tmp_path, text))


def test_it_rejects_a_frame_with_the_wrong_number_of_values(tmp_path):
    text = HEADER + "Frames: 3\nFrame Time: 0.01\n" + FRAME + "0 1 2 3 4 5 6 7\n" + FRAME
    with pytest.raises(CaptureError, match=r"bad\.bvh:20: frame 1: expected 9 values, found 8"):
        motionlib.read(bvh(tmp_path, text))


def test_it_rejects_compensating_value_counts_on_two_lines(tmp_path):
    text = HEADER + "Frames: 2\nFrame Time: 0.01\n0 1 2 3 4 5 6 7 8 9\n0 1 2 3 4 5 6 7\n"
    with pytest.raises(CaptureError, match=r"bad\.bvh:19: frame 0: expected 9 values, found 10"):
        motionlib.read(bvh(tmp_path, text))


def test_it_rejects_a_non_numeric_value(tmp_path):
    text = HEADER + "Frames: 2\nFrame Time: 0.01\n" + FRAME + "0 1 2 3 x4 5 6 7 8\n"
    with pytest.raises(CaptureError, match=r"bad\.bvh:20: frame 1, value 5: 'x4' is not a number"):
        motionlib.read(bvh(tmp_path, text))


@pytest.mark.parametrize("bad", ["nan", "inf", "-Infinity"])
def test_it_rejects_nan_and_infinity(tmp_path, bad):
    text = HEADER + "Frames: 2\nFrame Time: 0.01\n" + FRAME + f"0 1 2 3 {bad} 5 6 7 8\n"
    with pytest.raises(CaptureError, match=rf"bad\.bvh:20: frame 1, value 5: '{bad}' is not a "
                                           "finite number"):
        motionlib.read(bvh(tmp_path, text))


def test_it_rejects_an_unknown_channel(tmp_path):
    text = HEADER.replace("CHANNELS 3 Zrotation", "CHANNELS 3 Wrotation")
    with pytest.raises(CaptureError, match=r"bad\.bvh:9: unknown channel 'Wrotation' for joint "
                                           "Head"):
        motionlib.read(bvh(tmp_path, text + "Frames: 0\nFrame Time: 0.01\n"))


def test_it_rejects_more_frame_lines_than_declared(tmp_path):
    text = HEADER + "Frames: 1\nFrame Time: 0.01\n" + FRAME * 2
    with pytest.raises(CaptureError, match=r"bad\.bvh:20: more frame lines than the 1 declared"):
        motionlib.read(bvh(tmp_path, text))


def test_it_rejects_a_missing_motion_section(tmp_path):
    with pytest.raises(CaptureError, match=r"bad\.bvh:\d+: no MOTION section"):
        motionlib.read(bvh(tmp_path, HEADER.replace("MOTION\n", "")))


def test_it_rejects_an_unclosed_joint(tmp_path):
    text = HEADER.replace("  }\n}\nMOTION", "MOTION")
    with pytest.raises(CaptureError, match=r"bad\.bvh:\d+: unexpected end of HIERARCHY"):
        motionlib.read(bvh(tmp_path, text))


def test_it_rejects_a_bad_offset(tmp_path):
    with pytest.raises(CaptureError, match=r"bad\.bvh:8: OFFSET of Head must be a number, "
                                           "found 'one'"):
        motionlib.read(bvh(tmp_path, HEADER.replace("OFFSET 0 1 0", "OFFSET 0 one 0", 1)))


def test_it_rejects_a_zero_frame_time(tmp_path):
    with pytest.raises(CaptureError, match=r"bad\.bvh:18: frame time must be a positive"):
        motionlib.read(bvh(tmp_path, HEADER + "Frames: 1\nFrame Time: 0\n" + FRAME))


def test_it_rejects_an_unknown_extension(tmp_path):
    path = tmp_path / "take.trc"
    path.write_text("x")
    with pytest.raises(CaptureError, match=r"take\.trc: unknown capture format '\.trc'"):
        motionlib.read(path)


def test_it_rejects_a_missing_file(tmp_path):
    with pytest.raises(CaptureError, match=r"gone\.bvh: no such file"):
        motionlib.read(tmp_path / "gone.bvh")


def test_it_asks_for_the_asf_of_an_amc(tmp_path):
    with pytest.raises(CaptureError, match=r"bad\.amc: an \.amc motion needs its \.asf"):
        motionlib.read(amc(tmp_path, AMC_FRAME.format(n=1)))


def test_it_rejects_an_amc_bone_missing_from_the_asf(tmp_path):
    text = AMC_FRAME.format(n=1) + "2\nroot 0 0 0 0 0 0\nupperback 1 2 3\n"
    with pytest.raises(CaptureError, match=r"bad\.amc:8: bone 'upperback' is not in the "
                                           r"skeleton s\.asf"):
        motionlib.read(amc(tmp_path, text), asf=tmp_path / "s.asf")


def test_it_rejects_amc_frame_numbers_out_of_sequence(tmp_path):
    text = AMC_FRAME.format(n=1) + AMC_FRAME.format(n=2) + AMC_FRAME.format(n=4)
    with pytest.raises(CaptureError, match=r"bad\.amc:9: frame number 4 out of sequence, "
                                           "expected 3"):
        motionlib.read(amc(tmp_path, text), asf=tmp_path / "s.asf")


def test_it_rejects_an_amc_line_with_the_wrong_number_of_values(tmp_path):
    text = AMC_FRAME.format(n=1) + "2\nroot 0 0 0 0 0 0\nlowerback 1 2\n"
    with pytest.raises(CaptureError, match=r"bad\.amc:8: bone 'lowerback' needs 3 values, "
                                           "found 2"):
        motionlib.read(amc(tmp_path, text), asf=tmp_path / "s.asf")


def test_it_rejects_a_non_finite_amc_value(tmp_path):
    text = AMC_FRAME.format(n=1) + "2\nroot 0 0 0 0 0 0\nlowerback 1 nan 3\n"
    with pytest.raises(CaptureError, match=r"bad\.amc:8: value 'nan' of bone 'lowerback' is not "
                                           "a finite number"):
        motionlib.read(amc(tmp_path, text), asf=tmp_path / "s.asf")


def test_it_rejects_an_empty_amc(tmp_path):
    (tmp_path / "s.asf").write_text(ASF)
    (tmp_path / "e.amc").write_text("")
    with pytest.raises(CaptureError, match=r"e\.amc:1: empty file"):
        motionlib.read(tmp_path / "e.amc", asf=tmp_path / "s.asf")


def test_it_rejects_an_asf_hierarchy_naming_an_undefined_bone(tmp_path):
    motion = amc(tmp_path, AMC_FRAME.format(n=1))
    (tmp_path / "s.asf").write_text(ASF.replace("root lowerback", "root lowerback thorax"))
    with pytest.raises(CaptureError, match=r"s\.asf:23: bone 'thorax' in :hierarchy is not "
                                           "defined in :bonedata"):
        motionlib.read(motion, asf=tmp_path / "s.asf")


def test_it_rejects_an_unsupported_asf_dof(tmp_path):
    motion = amc(tmp_path, AMC_FRAME.format(n=1))
    (tmp_path / "s.asf").write_text(ASF.replace("dof rx ry rz", "dof rx ry l"))
    with pytest.raises(CaptureError, match=r"s\.asf:19: unsupported dof 'l' of bone lowerback"):
        motionlib.read(motion, asf=tmp_path / "s.asf")


def test_it_rejects_a_binary_file_without_dumping_it(tmp_path):
    path = tmp_path / "photo.bvh"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 400)
    with pytest.raises(CaptureError, match=r"photo\.bvh:1: expected 'HIERARCHY'") as caught:
        motionlib.read(path)
    assert len(str(caught.value)) < 200


def test_it_reads_a_file_that_starts_with_a_byte_order_mark(tmp_path):
    path = tmp_path / "bom.bvh"
    path.write_bytes(b"\xef\xbb\xbf" + (HEADER + "Frames: 1\nFrame Time: 0.01\n" + FRAME).encode())
    assert motionlib.read(path).skeleton.names == ["Hips", "Head"]
