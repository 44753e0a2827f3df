"""python -m motionlib info / convert / segment on FBX takes."""

import numpy as np

import motionlib
from motionlib.cli import main
from tests.fbx.files import shared_fbx


def run(capsys, *args):
    status = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


def fields(out):
    return {k: v.strip() for k, v in (line.split(":", 1) for line in out.splitlines())}


def test_it_describes_a_mixamo_fbx(capsys):
    status, out, _ = run(capsys, "info", shared_fbx("flair.fbx"))
    assert status == 0
    lines = fields(out)
    assert (lines["format"], lines["fps"], lines["frames"]) == ("fbx", "30", "31")
    assert lines["animation"] == "mixamo.com|Layer0"
    assert lines["body parts"] == "19 of 19 mapped"


def test_it_lists_the_animations_of_a_file_with_several(capsys, made_fbx):
    status, out, _ = run(capsys, "info", made_fbx / "two_actions.fbx", "--animation", "flair")
    assert status == 0
    lines = fields(out)
    assert lines["animations"] == "0: breakdance, 1: flair"
    assert (lines["animation"], lines["frames"]) == ("flair", "31")


def test_it_converts_a_trimmed_fbx_take_to_bvh(capsys, tmp_path):
    source = shared_fbx("breakdance_1990.fbx")
    out = tmp_path / "clip.bvh"
    status, printed, _ = run(capsys, "convert", source, out, "--start", "10", "--stop", "40")
    assert status == 0, printed
    take = motionlib.read(source)
    clip = motionlib.read(out)
    assert clip.skeleton.names == take.skeleton.names and clip.n_frames == 30
    expected = motionlib.forward_kinematics(take)[10:40]
    np.testing.assert_allclose(motionlib.forward_kinematics(clip), expected, atol=1e-3)


def test_it_segments_an_fbx_take(capsys):
    status, out, _ = run(capsys, "segment", shared_fbx("samba_dancing.fbx"))
    assert status == 0
    assert "(595 frames at 30 fps)" in out


def test_it_says_in_one_line_why_an_fbx_cannot_be_read(capsys, made_fbx):
    status, _, err = run(capsys, "info", made_fbx / "mesh_only.fbx")
    assert status == 2
    assert err == ("motionlib info: error: mesh_only.fbx: no armature (skeleton) in the file; "
                   "it holds mesh. Export the take with its skeleton and animation\n")
