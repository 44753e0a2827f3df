"""Limits on what a capture file may hold and expand to, checked before allocating, and the
hierarchy readers' linear, stack-based walk (issue 11, item 5)."""

import pytest

import motionlib
from motionlib import CaptureError
from motionlib.io import read_asf
from motionlib.take import Limits

ROOT_ONE_CHANNEL = "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 1 Yposition\n"


def flat_bvh(n_children, n_frames, frame="0\n"):
    """A root with one channel and ``n_children`` channel-less joints, then the frames."""
    joints = "".join(f"  JOINT j{i}\n  {{\n    OFFSET 0 1 0\n  }}\n" for i in range(n_children))
    return (ROOT_ONE_CHANNEL + joints + "}\nMOTION\n"
            f"Frames: {n_frames}\nFrame Time: 0.01\n" + frame * n_frames)


def chain_bvh(depth, n_frames=2):
    """A root and a chain of ``depth`` joints, each nested in the one before."""
    opening = "".join(f"JOINT j{i}\n{{\nOFFSET 0 1 0\nCHANNELS 1 Xrotation\n"
                      for i in range(depth))
    text = ("HIERARCHY\nROOT Hips\n{\nOFFSET 0 0 0\nCHANNELS 1 Yposition\n" + opening
            + "}\n" * (depth + 1) + f"MOTION\nFrames: {n_frames}\nFrame Time: 0.01\n")
    return text + (" ".join(["0"] * (depth + 1)) + "\n") * n_frames


def write(tmp_path, text, name="big.bvh"):
    path = tmp_path / name
    path.write_text(text)
    return path


def test_it_refuses_a_trillion_frames_before_allocating(tmp_path):
    text = flat_bvh(1, 0).replace("Frames: 0", "Frames: 1000000000000") + "0\n"
    with pytest.raises(CaptureError, match=r"big\.bvh:12: 1000000000000 frames is more than "
                                           r"the limit of 2000000"):
        motionlib.read(write(tmp_path, text))


def test_it_refuses_a_small_file_whose_positions_would_be_600_mb(tmp_path):
    # 1,000 joints (the root has the only channel) x 50,000 frames: a 500 KB file.
    path = write(tmp_path, flat_bvh(999, 50_000))
    with pytest.raises(CaptureError, match=r"50000 frames × 1000 joints = 50000000 joint "
                                           r"positions is more than the limit of 20000000"):
        motionlib.read(path)


def test_it_bounds_positions_by_the_size_of_the_file(tmp_path):
    # 5,000,000 joint positions (60 MB of float32) from a file of about 60 KB.
    path = write(tmp_path, flat_bvh(999, 5000))
    with pytest.raises(CaptureError, match=r"5000 frames × 1000 joints = 5000000 joint "
                                           r"positions is too many for a \d+-byte file"):
        motionlib.read(path)


def test_it_refuses_more_joints_than_the_limit(tmp_path):
    path = write(tmp_path, flat_bvh(1000, 2))
    # The 1,001st joint (j999) opens on line 4 * 999 + 6.
    with pytest.raises(CaptureError, match=r"big\.bvh:4002: more than 1000 joints \(the "
                                           r"limit\); joint j999 is one too many"):
        motionlib.read(path)


def test_it_takes_the_joint_limit_as_a_keyword(tmp_path):
    path = write(tmp_path, flat_bvh(3, 2))
    with pytest.raises(CaptureError, match=r"more than 3 joints"):
        motionlib.read(path, limits=Limits(max_joints=3))


def test_it_reads_a_hierarchy_nested_deeper_than_the_recursion_limit(tmp_path):
    take = motionlib.read(write(tmp_path, chain_bvh(3000)), limits=Limits(max_joints=5000))
    assert take.skeleton.n_joints == 3001
    assert list(take.skeleton.parents[:4]) == [-1, 0, 1, 2]


def test_it_reads_a_flat_hierarchy_of_many_joints(tmp_path):
    take = motionlib.read(write(tmp_path, flat_bvh(20_000, 2)),
                          limits=Limits(max_joints=20_001))
    assert take.skeleton.n_joints == 20_001 and set(take.skeleton.parents[1:]) == {0}


def test_it_writes_back_a_chain_deeper_than_the_recursion_limit(tmp_path):
    limits = Limits(max_joints=5000)
    take = motionlib.read(write(tmp_path, chain_bvh(3000)), limits=limits)
    motionlib.write_bvh(take, tmp_path / "out.bvh")
    again = motionlib.read(tmp_path / "out.bvh", limits=limits)
    assert again.skeleton.names == take.skeleton.names


ASF_HEAD = """:version 1.10
:name test
:units
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
"""
BONE = """  begin
     name {name}
     direction 0 1 0
     length 1
     axis 0 0 0 XYZ
{dof}  end
"""


def asf_text(names, hierarchy, dof="    dof rx ry rz\n"):
    bones = "".join(BONE.format(name=n, dof=dof) for n in names)
    return ASF_HEAD + bones + ":hierarchy\n  begin\n" + hierarchy + "  end\n"


def test_it_reads_an_asf_chain_deeper_than_the_recursion_limit(tmp_path):
    names = [f"b{i}" for i in range(3000)]
    chain = "".join(f"    {a} {b}\n" for a, b in zip(["root", *names], names, strict=False))
    asf = write(tmp_path, asf_text(names, chain), "deep.asf")
    skeleton = read_asf(asf, limits=Limits(max_joints=5000)).skeleton
    assert skeleton.n_joints == 3001 and list(skeleton.parents[-2:]) == [2998, 2999]


def test_it_refuses_an_asf_with_more_bones_than_the_limit(tmp_path):
    names = [f"b{i}" for i in range(5)]
    asf = write(tmp_path, asf_text(names, "    root " + " ".join(names) + "\n"), "many.asf")
    with pytest.raises(CaptureError, match=r"many\.asf:\d+: more than 5 joints \(the limit\); "
                                           r"bone b4 is one too many"):
        read_asf(asf, limits=Limits(max_joints=5))


def test_it_bounds_amc_positions_by_the_size_of_the_file(tmp_path):
    # 500 bones without channels, each frame lists only the root: 2,505,000 joint positions
    # (30 MB) from a file of about 100 KB.
    names = [f"b{i}" for i in range(500)]
    asf = write(tmp_path, asf_text(names, "    root " + " ".join(names) + "\n", dof=""),
                "wide.asf")
    amc = write(tmp_path, "".join(f"{n}\nroot 0 0 0 0 0 0\n" for n in range(1, 5011)), "wide.amc")
    with pytest.raises(CaptureError, match=r"wide\.amc:\d+: frame \d+ is one more than the "
                                           r"limits admit for 501 joints"):
        motionlib.read(amc, asf=asf)
