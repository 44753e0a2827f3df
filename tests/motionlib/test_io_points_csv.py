"""Joint-position CSV: the real UTKinect skeletons (irregular frame ids on a 30 Hz clock),
the writer's round trip, the ``time`` layout, and malformed files."""

import csv
import io

import numpy as np
import pytest

import motionlib
from motionlib.io.pointcsv import write_points_csv
from tests.motionlib.points_data import points_file


@pytest.fixture(scope="module")
def s01():
    return motionlib.read(points_file("utkinect", "s01_e01.csv"))


def rows_of(path):
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle))
    return rows[0], [[float(c) for c in row] for row in rows[1:]]


def test_it_reads_a_kinect_take_on_its_30_hz_clock(s01):
    header, rows = rows_of(points_file("utkinect", "s01_e01.csv"))
    ids = [int(r[0]) for r in rows]
    assert s01.format == "csv" and s01.fps == 30.0
    assert s01.first_number == ids[0] == 190
    assert s01.n_frames == ids[-1] - ids[0] + 1
    assert s01.n_points == 20 and s01.point_names[0] == "hip_center"
    assert s01.point_names[-1] == "foot_right"
    assert (s01.unit, s01.up, s01.marker_set) == ("m", "y", "kinect v1")


def test_each_frame_id_holds_its_first_row_and_frames_without_a_row_are_gaps(s01):
    _, rows = rows_of(points_file("utkinect", "s01_e01.csv"))
    first = {}
    for row in rows:
        first.setdefault(int(row[0]), row[1:])
    assert len(first) < len(rows)  # the file repeats some ids
    for frame_id, values in first.items():
        np.testing.assert_array_equal(s01.channels[frame_id - 190], values)
    empty = sorted(set(range(190, 190 + s01.n_frames)) - set(first))
    assert empty and np.isnan(s01.channels[np.array(empty) - 190]).all()


def test_the_kinect_joints_are_linked_as_the_body(s01):
    parent = {s01.point_names[j]: s01.point_names[p] if p >= 0 else None
              for j, p in enumerate(s01.skeleton.parents)}
    assert parent["hip_center"] is None
    assert parent["knee_left"] == "hip_left" and parent["hand_right"] == "wrist_right"
    assert parent["head"] == "shoulder_center"


def test_a_written_csv_reads_back_the_same(s01, tmp_path):
    write_points_csv(s01, tmp_path / "clip.csv", start=10, stop=400)
    back = motionlib.read(tmp_path / "clip.csv")
    assert back.point_names == s01.point_names
    assert (back.fps, back.unit, back.up) == (30.0, "m", "y")
    # Frames with nothing seen have no row: the clip starts and ends at a tracked frame.
    seen = np.flatnonzero(~np.isnan(s01.channels[10:400]).all(axis=1))
    assert back.first_number == 200 + seen[0]
    np.testing.assert_array_equal(back.channels, s01.channels[10 + seen[0]: 10 + seen[-1] + 1])


def test_it_writes_gaps_as_empty_cells():
    take = motionlib.read(points_file("utkinect", "s01_e01.csv")).slice(0, 3)
    channels = take.channels.copy()
    channels[0, 3:6] = np.nan
    from dataclasses import replace
    out = io.StringIO()
    write_points_csv(replace(take, channels=channels), out)
    line = out.getvalue().splitlines()[2]
    assert line.startswith("190,") and ",,," in line


def write(tmp_path, text):
    path = tmp_path / "take.csv"
    path.write_text(text)
    return path


def test_a_time_column_places_rows_at_the_rate_of_its_steps(tmp_path):
    take = motionlib.read(write(tmp_path, "time,a_x,a_y,a_z\n0.0,1,2,3\n0.01,1,2,3\n"
                                "0.03,1,2,\n0.04,4,5,6\n"))
    assert (take.fps, take.n_frames) == (100.0, 5)
    assert np.isnan(take.channels[2]).all() and np.isnan(take.channels[3, 2])


def test_a_comment_line_names_rate_unit_and_up_axis(tmp_path):
    take = motionlib.read(write(tmp_path, "# fps=120 unit=mm up=z\nframe,a_x,a_y,a_z\n"
                                "1,1,2,3\n2,1,2,3\n"))
    assert (take.fps, take.unit, take.up) == (120.0, "mm", "z")
    np.testing.assert_array_equal(take.positions[0, 0], [1, 3, -2])


def test_it_names_the_line_and_column_of_a_bad_number(tmp_path):
    path = write(tmp_path, "frame,a_x,a_y,a_z\n1,1,2,3\n2,1,two,3\n")
    with pytest.raises(motionlib.CaptureError,
                       match=r"take\.csv:3: column 3 \(a_y\): 'two' is not a number"):
        motionlib.read(path)


def test_it_names_a_column_that_breaks_the_layout(tmp_path):
    path = write(tmp_path, "frame,a_x,a_y,b_z\n1,1,2,3\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.csv:1: column 4: 'b_z' should "
                       r"be a_z"):
        motionlib.read(path)


def test_it_names_a_first_column_that_is_not_a_clock(tmp_path):
    path = write(tmp_path, "index,a_x,a_y,a_z\n1,1,2,3\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.csv:1: column 1: 'index' should "
                       r"be frame, frame_id or time"):
        motionlib.read(path)


def test_it_names_a_row_with_another_number_of_cells(tmp_path):
    path = write(tmp_path, "frame,a_x,a_y,a_z\n1,1,2,3\n2,1,2\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.csv:3: expected 4 cells, found 3"):
        motionlib.read(path)


def test_it_names_a_fractional_frame_number(tmp_path):
    path = write(tmp_path, "frame,a_x,a_y,a_z\n1,1,2,3\n2.5,1,2,3\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.csv:3: column 1 \(frame\): 2\.5 "
                       r"is not a whole frame number"):
        motionlib.read(path)


def test_it_names_an_unknown_setting(tmp_path):
    path = write(tmp_path, "# rate=30\nframe,a_x,a_y,a_z\n1,1,2,3\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.csv:1: setting 'rate=30'"):
        motionlib.read(path)


def test_it_refuses_frame_numbers_spanning_more_frames_than_the_file_may_hold(tmp_path):
    path = write(tmp_path, "frame,a_x,a_y,a_z\n1,1,2,3\n90000000,1,2,3\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.csv: frame numbers 1 to 90000000 "
                       r"span 90000000 frames, more than the \d+ a file of this size may hold"):
        motionlib.read(path)
