"""Point takes are held to the limits joints are held to, their headers are read in linear
time, and values no take can hold are refused at the line that gives them (issue 48, items
1, 5, 8 and 12)."""

import struct
import time

import numpy as np
import pytest

import motionlib
from motionlib import CaptureError
from motionlib.io import read_points_csv, read_qualisys_tsv, write_c3d
from motionlib.points import make_point_take
from motionlib.take import Limits
from tests.motionlib.points_data import points_file

# Limits wide enough to let a header of tens of thousands of points through, so that the
# time its parsing takes is what is measured.
WIDE = Limits(max_joints=10**6, max_joint_frames=10**9, max_expansion=10**6)


def points_csv(tmp_path, n_points, rows=("0", "1"), name="wide.csv", prefix=""):
    header = ",".join(f"m{k}_{a}" for k in range(n_points) for a in "xyz")
    lines = [f"frame,{header}"] + [f"{r}," + ",".join(["1.5"] * (3 * n_points)) for r in rows]
    path = tmp_path / name
    path.write_text(prefix + "\n".join(lines) + "\n")
    return path


def qualisys_tsv(tmp_path, names, name="wide.tsv"):
    head = (f"NO_OF_FRAMES\t2\nFREQUENCY\t100\nNO_OF_MARKERS\t{len(names)}\n"
            "MARKER_NAMES\t" + "\t".join(names) + "\n")
    rows = ("\t".join(["1.5"] * (3 * len(names))) + "\n") * 2
    path = tmp_path / name
    path.write_text(head + rows)
    return path


def seconds(read, path, **kwargs):
    """CPU seconds of the fastest of three reads: what the reading costs, not how busy the
    machine is."""
    best = float("inf")
    for _ in range(3):
        started = time.process_time()
        try:
            read(path, **kwargs)
        except CaptureError:
            pass
        best = min(best, time.process_time() - started)
    return best


# ---- points count as joints -----------------------------------------------------------------


def test_it_refuses_a_tsv_of_33334_markers_naming_the_count_and_the_line(tmp_path):
    path = qualisys_tsv(tmp_path, [f"m{k}" for k in range(33_334)])
    with pytest.raises(CaptureError, match=r"wide\.tsv:4: 33334 markers is more than the limit "
                                           r"of 1000 joints"):
        motionlib.read(path)


def test_it_refuses_a_csv_of_1001_points_at_its_header(tmp_path):
    path = points_csv(tmp_path, 1001)
    with pytest.raises(CaptureError, match=r"wide\.csv:1: 1001 points is more than the limit "
                                           r"of 1000 joints"):
        motionlib.read(path)


def test_it_reads_a_csv_of_exactly_1000_points(tmp_path):
    assert motionlib.read(points_csv(tmp_path, 1000)).n_points == 1000


def with_point_used(data: bytes, value: int) -> bytes:
    """A C3D file's bytes with its POINT:USED parameter (a 16-bit scalar) set to ``value``."""
    data = bytearray(data)
    group = 256 - data[data.index(b"POINT", 512) - 1]  # a group's id is stored negated
    name = data.index(bytes([4, group]) + b"USED", 512)
    word = name + 2 + 4 + 2  # after the name: offset (2), then bytes per element, dimensions
    assert (data[word], data[word + 1]) == (2, 0), "POINT:USED is not a 16-bit scalar"
    data[word + 2: word + 4] = struct.pack("<H", value)
    return bytes(data)


def test_it_refuses_a_c3d_whose_point_used_says_5000_naming_it(tmp_path):
    take = make_point_take(name="many", format="c3d", fps=100.0, coordinates=np.ones((3, 2, 3)),
                           names=["a", "b"], unit="mm", up="z")
    path = tmp_path / "many.c3d"
    write_c3d(take, path)
    path.write_bytes(with_point_used(path.read_bytes(), 5000))
    with pytest.raises(CaptureError, match=r"many\.c3d: 5000 points \(parameter POINT:USED\) is "
                                           r"more than the limit of 1000 joints"):
        motionlib.read(path)


def test_it_refuses_an_fbx_armature_of_more_bones_than_the_limit():
    from tests.fbx.files import shared_fbx

    path = shared_fbx("13_29_blender.fbx")
    with pytest.raises(CaptureError, match=r"13_29_blender\.fbx: \d+ bones in armature .* is "
                                           r"more than the limit of 10 joints"):
        motionlib.read(path, limits=Limits(max_joints=10))


# ---- headers are read in linear time --------------------------------------------------------


def test_a_csv_header_of_60000_points_costs_about_ten_times_one_of_6000(tmp_path):
    small = seconds(read_points_csv, points_csv(tmp_path, 6_000, name="s.csv"), limits=WIDE)
    large = seconds(read_points_csv, points_csv(tmp_path, 60_000, name="l.csv"), limits=WIDE)
    # Linear: about 10 times; the quadratic reading took about 100 times (seconds).
    assert large < 40 * max(small, 0.02), (small, large)


def test_a_tsv_naming_one_of_60000_markers_twice_is_refused_in_linear_time(tmp_path):
    def names(n):
        return [f"m{k}" for k in range(n - 1)] + [f"m{n - 2}"]  # the last one given twice

    small = seconds(read_qualisys_tsv, qualisys_tsv(tmp_path, names(6_000), "s.tsv"), limits=WIDE)
    path = qualisys_tsv(tmp_path, names(60_000), "l.tsv")
    large = seconds(read_qualisys_tsv, path, limits=WIDE)
    assert large < 40 * max(small, 0.02), (small, large)
    with pytest.raises(CaptureError, match=r"l\.tsv:4: MARKER_NAMES: 'm59998' is named twice"):
        read_qualisys_tsv(path, limits=WIDE)


# ---- values no take can hold ----------------------------------------------------------------


HEADER = "frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,2,3,4,5,6\n"
TIMES = "time,a_x,a_y,a_z,b_x,b_y,b_z\n0,1,2,3,4,5,6\n"

# (file name, its text, the message it is refused with)
BAD_CSV = [
    ("far.csv", HEADER + "1,1,2,3,4,1e39,6\n",
     r"far\.csv:3: column 6 \('b_y'\): 1e\+39 is beyond the largest coordinate a take may hold"),
    ("inf.csv", HEADER + "1,1,2,inf,4,5,6\n",
     r"inf\.csv:3: column 4 \(a_z\): 'inf' is not a finite number"),
    ("late.csv", HEADER + "10000000000000000000,1,2,3,4,5,6\n",
     r"late\.csv:3: column 1 \(frame\): frame 1e\+19 is outside 0 to 2147483647"),
    ("fast.csv", TIMES + "1e-300,1,2,3,4,5,6\n2e-300,1,2,3,4,5,6\n",
     r"fast\.csv:2: column 1 \(time\): steps of 1e-300 s make 1e\+300 frames per second, "
     r"outside 0\.1 to 10000"),
    ("long.csv", "# fps=100\n" + TIMES + "1e300,1,2,3,4,5,6\n",
     r"long\.csv:4: column 1 \(time\): 1e\+300 s is frame 1e\+302, beyond 2147483647"),
    ("blind.csv", "frame,a_x,a_y,a_z,b_x,b_y,b_z\n0,,,,,,\n1,nan,nan,nan,,,\n",
     r"blind\.csv: no point is seen in any of the 2 frames"),
]


@pytest.mark.parametrize(("name", "text", "message"), BAD_CSV, ids=[c[0] for c in BAD_CSV])
def test_it_refuses_a_csv_value_no_take_can_hold_naming_line_and_column(tmp_path, name, text,
                                                                        message):
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(CaptureError, match=message):
        motionlib.read(path)


def test_it_refuses_a_tsv_coordinate_beyond_the_limit(tmp_path):
    path = qualisys_tsv(tmp_path, ["a", "b"])
    path.write_text(path.read_text().replace("1.5", "-3e38", 1))
    with pytest.raises(CaptureError, match=r"wide\.tsv:5: column 1 \('a X'\): -3e\+38 is beyond"):
        motionlib.read(path)


def test_it_refuses_a_c3d_coordinate_beyond_the_limit_naming_frame_and_point(tmp_path):
    coordinates = np.ones((4, 2, 3))
    coordinates[2, 1, 0] = 3e37
    take = make_point_take(name="far", format="c3d", fps=100.0, coordinates=coordinates,
                           names=["a", "b"], unit="mm", up="z", first_number=10)
    write_c3d(take, tmp_path / "far.c3d")
    with pytest.raises(CaptureError, match=r"far\.c3d: data section, frame 12, point 2: 3e\+37 "
                                           r"is beyond the largest coordinate"):
        motionlib.read(tmp_path / "far.c3d")


# ---- a byte-order mark is not part of the first word ----------------------------------------


def test_a_csv_saved_with_a_byte_order_mark_reads_as_without(tmp_path):
    original = points_file("utkinect", "s01_e01.csv")
    marked = tmp_path / "s01_e01.csv"
    marked.write_bytes(b"\xef\xbb\xbf" + original.read_bytes())
    a, b = motionlib.read(original), motionlib.read(marked)
    assert a.point_names == b.point_names
    np.testing.assert_array_equal(a.channels, b.channels)


def test_a_tsv_saved_with_a_byte_order_mark_reads_as_without(tmp_path):
    original = points_file("vmci", "subject1_run1.tsv")
    marked = tmp_path / "subject1_run1.tsv"
    marked.write_bytes(b"\xef\xbb\xbf" + original.read_bytes())
    a, b = motionlib.read(original), motionlib.read(marked)
    assert (a.fps, a.point_names) == (b.fps, b.point_names)
    np.testing.assert_array_equal(a.channels, b.channels)


# ---- what is admitted can be written back ---------------------------------------------------


def test_a_take_of_600_points_is_written_as_c3d_and_read_back(tmp_path):
    # A C3D parameter holds at most 255 labels: the rest go in POINT:LABELS2, LABELS3.
    rng = np.random.default_rng(0)
    names = [f"marker{k}" for k in range(600)]
    take = make_point_take(name="many", format="csv", fps=100.0,
                           coordinates=rng.normal(size=(4, 600, 3)), names=names, unit="mm",
                           up="z")
    write_c3d(take, tmp_path / "many.c3d")
    back = motionlib.read(tmp_path / "many.c3d")
    assert back.point_names == names
    np.testing.assert_allclose(back.channels, take.channels, rtol=1e-6)


def test_it_refuses_a_point_name_longer_than_the_limit_naming_the_line(tmp_path):
    path = tmp_path / "long.csv"
    name = "p" * 201
    path.write_text(f"frame,{name}_x,{name}_y,{name}_z\n0,1,2,3\n1,1,2,3\n")
    with pytest.raises(CaptureError, match=r"long\.csv:1: point name 'ppp.*\(201 characters\) "
                                           r"is longer than the limit of 200 characters"):
        motionlib.read(path)
