"""``check_bvh``: a BVH file's structure checked from its head, with ``read_bvh``'s
messages, without reading its frames."""

import io

import pytest

from motionlib import synth, write_bvh
from motionlib.errors import CaptureError
from motionlib.io import bvh as bvh_module
from motionlib.io import check_bvh, read_bvh
from motionlib.take import DEFAULT_LIMITS


def take_lines(seed=1, duration=5.0):
    take, _ = synth.generate(seed=seed, fps=120.0, duration=duration)
    text = io.StringIO()
    write_bvh(take, text)
    return text.getvalue().splitlines()


def write(tmp_path, lines, name="take.bvh", end="\n"):
    path = tmp_path / name
    path.write_bytes(end.join(lines).encode() + end.encode())
    return path


def test_it_returns_what_read_bvh_reads_of_the_header(tmp_path):
    path = write(tmp_path, take_lines())
    skeleton, n_frames, frame_time = check_bvh(path)
    take = read_bvh(path)
    assert (skeleton.names, n_frames, frame_time) == (take.skeleton.names, take.n_frames,
                                                      take.frame_time)


def test_it_reads_only_the_head_of_a_long_file(tmp_path, monkeypatch):
    path = write(tmp_path, take_lines(duration=60.0))
    monkeypatch.setattr(bvh_module, "HEAD_BLOCK", 4096)
    read = []
    real_open = open

    def counting_open(file, mode="r", *args, **kwargs):
        handle = real_open(file, mode, *args, **kwargs)
        original = handle.read
        handle.read = lambda n=-1: read.append(len(chunk := original(n))) or chunk
        return handle

    monkeypatch.setattr("builtins.open", counting_open)
    check_bvh(path)
    assert 0 < sum(read) < path.stat().st_size / 50


@pytest.mark.parametrize("line_ends", ["\n", "\r\n", "\r"])
def test_it_names_a_bad_frame_count_as_read_bvh_does(tmp_path, line_ends):
    lines = take_lines()
    motion = lines.index("MOTION")
    lines[motion + 1] = "Frames: many"
    path = write(tmp_path, lines, end=line_ends)
    with pytest.raises(CaptureError) as checked:
        check_bvh(path)
    with pytest.raises(CaptureError) as read:
        read_bvh(path)
    assert str(checked.value) == str(read.value)
    assert f"take.bvh:{motion + 2}:" in str(checked.value)


def test_it_names_a_broken_hierarchy(tmp_path):
    path = write(tmp_path, ["HIERARCHY", "ROOT Hips", "{"])
    with pytest.raises(CaptureError, match=r"take\.bvh:\d+:"):
        check_bvh(path)


def test_it_refuses_a_file_without_motion(tmp_path):
    lines = take_lines()
    path = write(tmp_path, lines[:lines.index("MOTION")])
    with pytest.raises(CaptureError, match="no MOTION section"):
        check_bvh(path)


def test_it_refuses_more_frames_than_the_file_can_hold(tmp_path):
    lines = take_lines()
    motion = lines.index("MOTION")
    lines[motion + 1] = f"Frames: {DEFAULT_LIMITS.max_frames + 1}"
    path = write(tmp_path, lines)
    with pytest.raises(CaptureError, match="more than the limit"):
        check_bvh(path)


def test_it_leaves_a_bad_frame_value_to_read_bvh(tmp_path):
    lines = take_lines()
    tokens = lines[-2].split()
    lines[-2] = " ".join(tokens[:1] + ["nan-ish"] + tokens[2:])
    path = write(tmp_path, lines)
    check_bvh(path)
    with pytest.raises(CaptureError, match="nan-ish"):
        read_bvh(path)
