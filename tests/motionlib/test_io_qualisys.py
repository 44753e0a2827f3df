"""Qualisys TSV marker exports: the real vMCI pick-and-place takes, and malformed files."""

import csv

import numpy as np
import pytest

import motionlib
from tests.motionlib.points_data import points_file


@pytest.fixture(scope="module")
def run1():
    return motionlib.read(points_file("vmci", "subject1_run1.tsv"))


def test_it_reads_frames_rate_and_markers_of_a_real_export(run1):
    assert run1.format == "tsv"
    assert (run1.n_frames, run1.fps, run1.n_points, run1.first_number) == (738, 60.0, 13, 690)
    assert run1.point_names == ["Shoulder", "Elbow", "Hand top", "Hand right", "Hand left",
                                "Thumb", "Index", "Middle", "Back top", "Back right",
                                "Back left", "Box back", "Box left"]
    assert (run1.unit, run1.up, run1.marker_set) == ("mm", "z", None)
    assert (run1.skeleton.parents == -1).all()


def rows_of(path):
    with open(path, newline="") as handle:
        rows = list(csv.reader(handle, delimiter="\t"))
    return rows[11:]


def test_its_values_and_gaps_are_the_cells_of_the_file(run1):
    rows = rows_of(points_file("vmci", "subject1_run1.tsv"))
    cells = np.array([[float(c) if c else np.nan for c in row[2:41]] for row in rows])
    assert np.isnan(cells).any()  # the file has markers not seen
    np.testing.assert_array_equal(run1.channels, cells)


def test_markers_are_named_in_the_order_of_the_columns():
    take = motionlib.read(points_file("vmci", "subject2_run1.tsv"))
    assert take.point_names[:3] == ["Back top", "Back right", "Back left"]
    assert take.first_number == 625


def write(tmp_path, text):
    path = tmp_path / "take.tsv"
    path.write_text(text)
    return path


HEAD = ("NO_OF_FRAMES\t3\nNO_OF_MARKERS\t2\nFREQUENCY\t100\nMARKER_NAMES\tA\tB\n"
        "Frame\tTime\tA X\tA Y\tA Z\tB X\tB Y\tB Z\t\n")


def test_it_places_rows_by_their_frame_numbers(tmp_path):
    take = motionlib.read(write(tmp_path, HEAD + "5\t0.05\t1\t2\t3\t4\t5\t6\n"
                                "7\t0.07\t1\t2\t3\t\t\t\n"))
    assert (take.n_frames, take.first_number, take.fps) == (3, 5, 100.0)
    assert np.isnan(take.channels[1]).all()
    assert np.isnan(take.channels[2, 3:]).all() and take.channels[2, 0] == 1


def test_it_names_the_line_and_column_of_a_bad_number(tmp_path):
    path = write(tmp_path, HEAD + "1\t0.01\t1\t2\t3\t4\t5\t6\n2\t0.02\t1\t2\tx3\t4\t5\t6\n")
    with pytest.raises(motionlib.CaptureError,
                       match=r"take\.tsv:7: column 5 \(A Z\): 'x3' is not a number"):
        motionlib.read(path)


def test_it_names_the_line_of_a_row_with_missing_cells(tmp_path):
    path = write(tmp_path, HEAD + "1\t0.01\t1\t2\t3\t4\t5\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.tsv:6: expected 8 cells, found 7"):
        motionlib.read(path)


def test_it_names_a_missing_frequency(tmp_path):
    path = write(tmp_path, HEAD.replace("FREQUENCY\t100\n", ""))
    with pytest.raises(motionlib.CaptureError, match=r"no FREQUENCY line"):
        motionlib.read(path)


def test_it_names_a_frequency_that_is_not_a_number(tmp_path):
    path = write(tmp_path, HEAD.replace("FREQUENCY\t100", "FREQUENCY\tfast") + "1\t0\t1\t2\t3\t4\t5\t6\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.tsv:3: FREQUENCY: 'fast' is not"):
        motionlib.read(path)


def test_it_names_a_column_line_that_does_not_match_the_markers(tmp_path):
    path = write(tmp_path, HEAD.replace("B X", "C X") + "1\t0\t1\t2\t3\t4\t5\t6\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.tsv:5: column 6: the column line "
                       r"does not match MARKER_NAMES"):
        motionlib.read(path)


def test_it_names_frames_out_of_order(tmp_path):
    path = write(tmp_path, HEAD + "2\t0\t1\t2\t3\t4\t5\t6\n1\t0\t1\t2\t3\t4\t5\t6\n")
    with pytest.raises(motionlib.CaptureError, match=r"take\.tsv:7: column 1 \(Frame\): frame "
                       r"1 comes after frame 2"):
        motionlib.read(path)


# A Qualisys Track Manager export as it comes: ten header lines, the column line, then rows
# with `0.000 0.000 0.000` where a marker was not seen (older exports write zeros there).
REAL_HEAD = ("NO_OF_FRAMES\t3\nNO_OF_CAMERAS\t7\nNO_OF_MARKERS\t2\nFREQUENCY\t60\n"
             "NO_OF_ANALOG\t0\nANALOG_FREQUENCY\t0\nDESCRIPTION\t--\n"
             "TIME_STAMP\t2015-11-12, 11:51:16\t6281.31358754\nDATA_INCLUDED\t3D\n"
             "MARKER_NAMES\tShoulder\tElbow\n"
             "Frame\tTime\tShoulder X\tShoulder Y\tShoulder Z\tElbow X\tElbow Y\tElbow Z\t\n")
ZERO_ROWS = ("1\t0.00000\t477.630\t335.852\t153.909\t0.000\t0.000\t0.000\t\n"
             "2\t0.01667\t0.000\t0.000\t0.000\t428.860\t335.450\t-73.206\t\n"
             "3\t0.03333\t0.000\t335.852\t153.909\t428.860\t0.000\t-73.206\t\n")


def test_a_marker_written_as_three_zeros_is_a_gap(tmp_path):
    take = motionlib.read(write(tmp_path, REAL_HEAD + ZERO_ROWS))
    assert (take.n_frames, take.fps, take.point_names) == (3, 60.0, ["Shoulder", "Elbow"])
    assert np.isnan(take.channels[0, 3:]).all() and np.isnan(take.channels[1, :3]).all()
    assert np.isnan(take.positions[0, 1]).all() and np.isnan(take.positions[1, 0]).all()
    np.testing.assert_array_equal(take.channels[0, :3], [477.630, 335.852, 153.909])


def test_a_single_zero_coordinate_is_a_value(tmp_path):
    take = motionlib.read(write(tmp_path, REAL_HEAD + ZERO_ROWS))
    np.testing.assert_array_equal(take.channels[2], [0.0, 335.852, 153.909, 428.860, 0.0, -73.206])


def test_three_zeros_are_a_gap_in_an_export_without_a_column_line(tmp_path):
    head = REAL_HEAD[:REAL_HEAD.index("Frame\t")]
    rows = "".join("\t".join(row.split("\t")[2:]) for row in ZERO_ROWS.splitlines(keepends=True))
    take = motionlib.read(write(tmp_path, head + rows))
    assert take.n_frames == 3
    assert np.isnan(take.channels[0, 3:]).all() and np.isnan(take.channels[1, :3]).all()
