"""C3D marker files: the real HDM05 Vicon take, checked against an independent reader
(ezc3d, C++), a round trip through the writer, and malformed files."""

import warnings
from dataclasses import replace

import numpy as np
import pytest

import motionlib
from motionlib.io.c3dfile import read_c3d, write_c3d
from tests.motionlib.points_data import HDM05, points_file

ezc3d = pytest.importorskip("ezc3d")


@pytest.fixture(scope="module")
def hdm05():
    return motionlib.read(points_file(*HDM05))


def test_it_reads_the_hdm05_take_with_its_frames_rate_and_markers(hdm05):
    assert hdm05.format == "c3d"
    assert (hdm05.n_frames, hdm05.fps, hdm05.n_points) == (5920, 120.0, 44)
    assert hdm05.first_number == 1
    assert hdm05.unit == "mm" and hdm05.up == "z"
    assert hdm05.point_names[:4] == ["*0", "*1", "*2", "Bastian:LFHD"]
    assert "Bastian:RMT5" in hdm05.point_names
    assert hdm05.marker_set == "plug-in gait"
    assert hdm05.channels.shape == (5920, 132)


def test_its_coordinates_equal_an_independent_readers_frame_by_frame(hdm05):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        other = ezc3d.c3d(str(points_file(*HDM05)))
    xyz = np.moveaxis(other["data"]["points"][:3], [0, 1, 2], [2, 1, 0])  # frames, points, xyz
    np.testing.assert_array_equal(hdm05.channels.reshape(5920, 44, 3), xyz)
    labels = [label for label in other["parameters"]["POINT"]["LABELS"]["value"]]
    assert labels == hdm05.point_names


def test_its_world_positions_are_y_up(hdm05):
    at = {n.split(":")[-1]: i for i, n in enumerate(hdm05.point_names)}
    head, ankle = hdm05.positions[:, at["LFHD"], 1], hdm05.positions[:, at["LANK"], 1]
    assert (head - ankle > 1000).mean() > 0.9  # a standing adult's head, in mm
    np.testing.assert_array_equal(hdm05.positions[:, :, 1], hdm05.channels[:, 2::3])
    np.testing.assert_array_equal(hdm05.positions[:, :, 2], -hdm05.channels[:, 1::3])


def test_forward_kinematics_of_a_point_take_is_a_copy_of_its_points(hdm05):
    positions = motionlib.forward_kinematics(hdm05)
    np.testing.assert_array_equal(positions, hdm05.positions)
    assert positions.flags.writeable and not np.shares_memory(positions, hdm05.positions)


def with_gaps(take):
    channels = take.channels.copy()
    channels[3, 0:3] = np.nan
    channels[10:20, 9:12] = np.nan
    return replace(take, channels=channels)


def test_a_trimmed_c3d_reads_back_with_the_same_markers_rate_frames_and_gaps(hdm05, tmp_path):
    take = with_gaps(hdm05.slice(0, 600))
    write_c3d(take, tmp_path / "clip.c3d", start=2, stop=500)
    back = read_c3d(tmp_path / "clip.c3d")
    assert back.point_names == take.point_names
    assert (back.fps, back.n_frames, back.first_number, back.unit, back.up) == \
        (120.0, 498, 3, "mm", "z")
    np.testing.assert_array_equal(back.channels, take.channels[2:500])
    assert np.isnan(back.channels[1, 0:3]).all() and np.isnan(back.channels[8:18, 9:12]).all()


def test_a_trimmed_c3d_opens_in_an_independent_reader(hdm05, tmp_path):
    take = with_gaps(hdm05)
    write_c3d(take, tmp_path / "clip.c3d", start=1000, stop=1240)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        other = ezc3d.c3d(str(tmp_path / "clip.c3d"))
    assert other["parameters"]["POINT"]["RATE"]["value"][0] == 120.0
    assert other["parameters"]["POINT"]["LABELS"]["value"] == take.point_names
    assert other["header"]["points"]["first_frame"] + 1 == 1001  # ezc3d counts from 0
    xyz = np.moveaxis(other["data"]["points"][:3], [0, 1, 2], [2, 1, 0])
    np.testing.assert_array_equal(xyz, take.channels[1000:1240].reshape(240, 44, 3))


def test_gaps_in_a_written_file_are_gaps_for_an_independent_reader(hdm05, tmp_path):
    write_c3d(with_gaps(hdm05.slice(0, 30)), tmp_path / "gaps.c3d")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        other = ezc3d.c3d(str(tmp_path / "gaps.c3d"))
    assert np.isnan(other["data"]["points"][:3, 0, 3]).all()
    assert other["data"]["meta_points"]["residuals"][0, 0, 3] < 0
    assert not np.isnan(other["data"]["points"][:3, 0, 4]).any()


@pytest.fixture(scope="module")
def original():
    return points_file(*HDM05).read_bytes()


def broken(tmp_path, data):
    path = tmp_path / "broken.c3d"
    path.write_bytes(bytes(data))
    return path


def test_it_names_the_data_block_when_the_file_is_truncated(original, tmp_path):
    path = broken(tmp_path, original[: len(original) // 2])
    with pytest.raises(motionlib.CaptureError, match=r"broken\.c3d: data section \(from block "
                       r"10\): the file ends in frame 2957 of the 5920 frames"):
        motionlib.read(path)


def test_it_names_the_header_byte_of_a_file_that_is_not_c3d(original, tmp_path):
    path = broken(tmp_path, original[:1] + b"\x00" + original[2:])
    with pytest.raises(motionlib.CaptureError, match=r"header block 1, byte 2: 0x00 is not "
                       r"the C3D key"):
        motionlib.read(path)


def test_it_refuses_a_file_shorter_than_its_header(tmp_path):
    with pytest.raises(motionlib.CaptureError, match=r"the file has 100 bytes, a C3D header "
                       r"needs 512"):
        motionlib.read(broken(tmp_path, b"\x02\x50" + b"\x00" * 98))


def test_it_names_the_parameter_block_of_an_unknown_processor(original, tmp_path):
    path = broken(tmp_path, original[:515] + b"\x10" + original[516:])
    with pytest.raises(motionlib.CaptureError, match=r"parameter block 2, byte 4: processor "
                       r"type 16"):
        motionlib.read(path)


def test_it_names_the_parameter_it_cannot_find_in_a_garbled_parameter_section(original,
                                                                             tmp_path):
    path = broken(tmp_path, original[:516] + b"\xff" * 1500 + original[2016:])
    with pytest.raises(motionlib.CaptureError, match=r"parameter POINT:USED is missing"):
        motionlib.read(path)


def test_it_names_a_parameter_section_that_points_past_the_file(original, tmp_path):
    path = broken(tmp_path, b"\xf0" + original[1:4000])
    with pytest.raises(motionlib.CaptureError, match=r"header block 1, byte 1: the parameter "
                       r"section starts at block 240, the file has 7 blocks"):
        motionlib.read(path)


def test_an_int16_c3d_reads_as_an_independent_reader_reads_it_with_its_gaps(tmp_path):
    """Scaled 16-bit integer points (POINT:SCALE > 0), as many Vicon files store them."""
    import c3d

    rng = np.random.default_rng(0)
    writer = c3d.Writer(point_rate=100.0, point_scale=0.1)
    writer.set_point_labels(["A", "B"])
    frames = []
    for i in range(20):
        points = np.zeros((2, 5), np.float32)
        points[:, :3] = rng.uniform(-500, 500, (2, 3))
        points[:, 3] = -1.0 if i == 5 else 1.0
        frames.append((points, np.zeros((0, 0))))
    writer.add_frames(frames)
    path = tmp_path / "int16.c3d"
    with warnings.catch_warnings(), open(path, "wb") as handle:
        warnings.simplefilter("ignore")
        writer.write(handle)
    take = read_c3d(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        other = ezc3d.c3d(str(path))["data"]["points"][:3]
    xyz = np.moveaxis(other, [0, 1, 2], [2, 1, 0]).reshape(20, 6)
    assert (take.n_frames, take.fps, take.point_names) == (20, 100.0, ["A", "B"])
    np.testing.assert_array_equal(take.channels, xyz)
    assert np.isnan(take.channels[5]).all()


def test_the_parameters_win_over_a_header_that_disagrees_with_them(original, hdm05, tmp_path):
    # Header words 2 (point count) and 11-12 (rate) repeat POINT:USED and POINT:RATE for old
    # programs; the C3D specification makes the parameters authoritative.
    data = bytearray(original)
    data[2:4] = (131).to_bytes(2, "little")
    data[20:22] = b"\xff\xff"
    take = motionlib.read(broken(tmp_path, data))
    assert (take.n_points, take.fps, take.n_frames) == (44, 120.0, 5920)
    np.testing.assert_array_equal(take.channels, hdm05.channels)


def test_it_names_the_frame_range_parameters_it_cannot_read(original, tmp_path):
    data = bytearray(original)
    data[578:580] = b"\x00\x00"  # a dimension of TRIAL:ACTUAL_START_FIELD / END_FIELD: empty
    with pytest.raises(motionlib.CaptureError, match=r"broken\.c3d: header words 4-5 and "
                       r"parameters TRIAL:ACTUAL_START_FIELD.*the frame range cannot be read"):
        motionlib.read(broken(tmp_path, data))


# Vicon's Plug-in Gait full-body marker set, from its product guide: head, trunk, arms with
# their wand markers (UPA, FRM), pelvis, legs with theirs (THI, TIB), feet.
PLUG_IN_GAIT = ["LFHD", "RFHD", "LBHD", "RBHD", "C7", "T10", "CLAV", "STRN", "RBAK",
                "LSHO", "LUPA", "LELB", "LFRM", "LWRA", "LWRB", "LFIN",
                "RSHO", "RUPA", "RELB", "RFRM", "RWRA", "RWRB", "RFIN",
                "LASI", "RASI", "LPSI", "RPSI", "LTHI", "LKNE", "LTIB", "LANK", "LHEE", "LTOE",
                "RTHI", "RKNE", "RTIB", "RANK", "RHEE", "RTOE"]


def roots_of(parents: list[int]) -> set[int]:
    """The point each point's chain of links ends at."""
    def root(i):
        seen = set()
        while parents[i] != -1:
            assert i not in seen, "the links form a cycle"
            seen.add(i)
            i = parents[i]
        return i
    return {root(i) for i in range(len(parents))}


def test_every_plug_in_gait_marker_of_hdm05_is_drawn_in_one_body(hdm05):
    """Regression: T10 and STRN were roots of their own (the trunk apart from the waist) and
    the wand markers (LUPA, LFRM, LTHI, LSHN, ...) and RBAC were drawn unlinked."""
    named = [i for i, n in enumerate(hdm05.point_names) if not n.startswith("*")]
    parents = hdm05.skeleton.parents
    assert len(named) == 41
    kept = {i: j for j, i in enumerate(named)}
    assert all(parents[i] in kept for i in named if parents[i] != -1)
    assert len(roots_of([kept.get(parents[i], -1) for i in named])) == 1
    # the unlabelled markers (*0, *1, *2) belong to no body part and stay apart
    assert all(parents[i] == -1 for i, n in enumerate(hdm05.point_names) if n.startswith("*"))


def test_the_full_plug_in_gait_set_is_one_tree():
    from motionlib import markersets

    names = [f"Subject:{n}" for n in PLUG_IN_GAIT]
    assert markersets.identify(names) == "plug-in gait"
    assert len(roots_of(markersets.link_parents(names, "plug-in gait"))) == 1
