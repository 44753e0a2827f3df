"""A long take read and walked in two threads at once (issue 50): the same values to the
bit as one thread, and the same refusals."""

import numpy as np
import pytest

import motionlib
from motionlib import kinematics, threads
from motionlib.io import numbers


@pytest.fixture
def two_threads(monkeypatch):
    """Split anything: two threads, from the first byte and frame."""
    monkeypatch.setenv("MOTIONLIB_THREADS", "2")
    monkeypatch.setattr(numbers, "PARALLEL_BYTES", 1)
    monkeypatch.setattr(kinematics, "PARALLEL_FRAMES", 1)


def one_thread(monkeypatch):
    monkeypatch.setenv("MOTIONLIB_THREADS", "1")


def test_it_reads_13_29_to_the_bit_as_one_thread_does(two_threads, monkeypatch, bvh_13_29):
    split = motionlib.read(bvh_13_29)
    positions = motionlib.forward_kinematics(split)
    one_thread(monkeypatch)
    whole = motionlib.read(bvh_13_29)
    np.testing.assert_array_equal(split.channels, whole.channels)
    np.testing.assert_array_equal(positions, motionlib.forward_kinematics(whole))


def text(rows):
    return "".join(" ".join(map(str, r)) + "\n" for r in rows).encode()


def test_it_moves_the_second_half_up_past_blank_lines_of_the_first(two_threads):
    data = b"\n\n\n" + text([[1, 2], [3, 4], [5, 6], [7, 8]])
    np.testing.assert_array_equal(numbers.read_rows(data, 0, 4, 2), [[1, 2], [3, 4], [5, 6], [7, 8]])


@pytest.mark.parametrize("bad", [0, 3], ids=["first half", "second half"])
def test_a_bad_value_in_either_half_sends_the_read_to_the_careful_path(two_threads, bad):
    rows = [[1, 2], [3, 4], [5, 6], [7, 8]]
    rows[bad] = [1, "x"]
    assert numbers.read_rows(text(rows), 0, 4, 2) is None


def test_more_lines_than_frames_is_refused_as_by_one_thread(two_threads):
    assert numbers.read_rows(text([[1, 2]] * 9), 0, 4, 2) is None
    assert numbers.read_rows(text([[1, 2]] * 3), 0, 4, 2) is None


def test_a_long_number_takes_pythons_conversion_in_a_thread_too(two_threads):
    long = "1.00000000000000000000000000001"
    values = numbers.read_rows(text([[long, 2]] * 6), 0, 6, 2)
    np.testing.assert_array_equal(values[:, 0], [float(long)] * 6)


def test_an_error_in_a_thread_is_raised_in_the_caller():
    def boom():
        raise ValueError("in the second thread")

    with pytest.raises(ValueError, match="in the second thread"):
        threads.run_all([lambda: 1, boom])


def test_it_uses_at_most_what_is_configured(monkeypatch):
    monkeypatch.setenv("MOTIONLIB_THREADS", "1")
    assert threads.threads() == 1
    monkeypatch.delenv("MOTIONLIB_THREADS")
    assert 1 <= threads.threads() <= threads.MAX_THREADS
    assert threads.bounds(5, 2) == [(0, 2), (2, 5)]
    assert threads.bounds(1, 2) == [(0, 1)]


def test_the_body_frame_and_low_pass_are_the_same_to_the_bit(monkeypatch):
    from motionlib import features

    rng = np.random.default_rng(50)
    positions = rng.normal(size=(3001, 7, 3))
    joints = {"root": 0, "left_hip": 1, "right_hip": 2}
    one_thread(monkeypatch)
    body = features.body_frame_positions(positions, joints, [3, 4, 6])
    smooth = features.lowpass(positions.reshape(3001, -1), fps=120, cutoff_hz=3)
    monkeypatch.setenv("MOTIONLIB_THREADS", "2")
    monkeypatch.setattr(features, "PARALLEL_FRAMES", 1)
    np.testing.assert_array_equal(features.body_frame_positions(positions, joints, [3, 4, 6]), body)
    np.testing.assert_array_equal(features.lowpass(positions.reshape(3001, -1), fps=120, cutoff_hz=3), smooth)
    np.testing.assert_array_equal(features.lowpass(positions, fps=120, cutoff_hz=3),
                                  smooth.reshape(positions.shape))
