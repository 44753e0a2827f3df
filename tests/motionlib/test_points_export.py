"""Clips of point takes: C3D and CSV through ``write_clip``; rotation formats refused with the
formats a point take is written in (and the reverse)."""

import numpy as np
import pytest

import motionlib
from motionlib import synth
from motionlib.io.export import write_clip
from tests.motionlib.points_data import points_file


@pytest.fixture(scope="module")
def kinect():
    return motionlib.read(points_file("utkinect", "s02_e01.csv"))


@pytest.mark.parametrize("fmt", ["c3d", "csv"])
def test_a_clip_of_a_point_take_reads_back_with_its_points_and_numbers(kinect, tmp_path, fmt):
    out = tmp_path / f"clip.{fmt}"
    write_clip(kinect, out, format=fmt, start=0, stop=300)
    clip = motionlib.read(out)
    assert clip.point_names == kinect.point_names and clip.fps == kinect.fps
    assert clip.first_number == kinect.first_number
    expected = kinect.channels[: clip.n_frames]
    if fmt == "c3d":  # C3D stores float32
        expected = expected.astype(np.float32)
    np.testing.assert_array_equal(clip.channels, expected)


@pytest.mark.parametrize("fmt", ["bvh", "fbx", "glb"])
def test_a_point_take_is_not_written_as_rotations(kinect, tmp_path, fmt):
    with pytest.raises(motionlib.CaptureError, match=rf"export format '{fmt}': a take of points "
                       r"\(markers or tracked joints\) is written as c3d or csv"):
        write_clip(kinect, tmp_path / f"clip.{fmt}", format=fmt)


def test_write_bvh_refuses_a_point_take(kinect, tmp_path):
    with pytest.raises(motionlib.CaptureError, match="has no joint rotations to write as BVH"):
        motionlib.write_bvh(kinect, tmp_path / "clip.bvh")


def test_a_take_of_rotations_is_not_written_as_c3d(tmp_path):
    take, _ = synth.generate(seed=1, duration=5.0)
    with pytest.raises(motionlib.CaptureError, match=r"export format 'c3d': a take of joint "
                       r"rotations is written as bvh or fbx or glb"):
        write_clip(take, tmp_path / "clip.c3d", format="c3d")


def test_info_says_which_marker_set_maps_a_point_take_to_body_parts(capsys):
    from motionlib.cli import main

    assert main(["info", str(points_file("utkinect", "s02_e01.csv"))]) == 0
    out = capsys.readouterr().out
    assert "format:          csv" in out
    assert "body parts:      19 of 19 mapped (Kinect v1 points)" in out


def test_info_says_when_points_follow_no_known_marker_set(capsys):
    from motionlib.cli import main

    assert main(["info", str(points_file("vmci", "subject1_run1.tsv"))]) == 0
    assert "not mapped (points of no known marker set" in capsys.readouterr().out
