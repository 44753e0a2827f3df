"""Reading FBX through Blender: the real Mixamo and CMU takes, Blender-made edge cases, bad files."""

import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import motionlib
from motionlib.errors import CaptureError
from motionlib.io import blender
from motionlib.io.fbx import Z_UP_TO_Y_UP, read_fbx_all, read_fbx_raw
from tests.fbx.files import shared_bvh_13_29, shared_fbx


@pytest.fixture(scope="module")
def take_13_29():
    return motionlib.read(shared_fbx("13_29_blender.fbx"))


@pytest.mark.slow
def test_it_reads_the_blender_export_of_13_29_as_the_bvh_moves(take_13_29):
    bvh = motionlib.read(shared_bvh_13_29())
    assert take_13_29.skeleton.names == bvh.skeleton.names
    assert (take_13_29.fps, take_13_29.frame_time) == (120.0, pytest.approx(bvh.frame_time))
    fbx_positions = motionlib.forward_kinematics(take_13_29)
    bvh_positions = motionlib.forward_kinematics(bvh)
    # Blender's exporter keys one frame more than the BVH has, holding the last pose.
    assert len(fbx_positions) == bvh.n_frames + 1
    np.testing.assert_array_equal(fbx_positions[-1], fbx_positions[-2])
    fbx_positions = fbx_positions[:-1]
    # One global scale: the BVH's unit became Blender's metre, written back as centimetres.
    scale = (np.linalg.norm(np.diff(fbx_positions[0], axis=0), axis=1).sum()
             / np.linalg.norm(np.diff(bvh_positions[0], axis=0), axis=1).sum())
    assert scale == pytest.approx(100.0, rel=1e-5)
    error = np.linalg.norm(fbx_positions / scale - bvh_positions, axis=-1).max(axis=1)
    assert error.max() < 1e-4 * motionlib.skeleton_height(bvh)


def test_it_finds_the_added_t_pose_of_a_cgspeed_take_in_its_fbx_copy(take_13_29):
    """Regression: the FBX copy of 13_29 kept its T-pose frame (rest_pose_frame None), so the
    speed lane's first value (the jump out of the T-pose) dwarfed the take's own speeds and
    clips exported from frame 0 started in T-pose."""
    from motionlib.segmenters import get_segmenter

    assert take_13_29.rest_pose_frame == 0 == motionlib.read(shared_bvh_13_29()).rest_pose_frame
    speed = get_segmenter("default")().fit_predict(take_13_29).signals["speed"]
    assert speed.max() < 10 * np.median(speed)


def test_it_finds_no_rest_pose_where_a_take_starts_moving():
    take = motionlib.read(shared_fbx("samba_dancing.fbx"))
    assert take.rest_pose_frame is None


def test_it_poses_a_mixamo_rig_as_blender_itself_does():
    path = shared_fbx("samba_dancing.fbx")
    take = motionlib.read(path)
    _, arrays = read_fbx_raw(path)
    frames = [0, 150, 377, take.n_frames - 1]
    reply = blender.shared().request(
        {"op": "evaluate", "path": str(path), "frames": [arrays["a0_frames"][f] for f in frames]},
        path=path, what="posing")
    heads = np.array(reply["heads"]) @ Z_UP_TO_Y_UP.T * 100.0
    columns = [take.skeleton.names.index(name) for name in reply["bones"]]
    positions = motionlib.forward_kinematics(take)[frames][:, columns]
    # Blender computes in float32: a few micrometres on a 1.8 m figure.
    np.testing.assert_allclose(positions, heads, atol=1e-3)


def test_it_reads_a_mixamo_take_with_its_frame_rate_and_frames():
    take = motionlib.read(shared_fbx("samba_dancing.fbx"))
    assert (take.format, take.fps, take.n_frames) == ("fbx", 30.0, 595)
    assert (take.name, take.animation) == ("samba_dancing", "mixamo.com|Layer0")
    assert take.skeleton.names[0] == "mixamorig:Hips"
    assert 150 < motionlib.skeleton_height(take) < 200  # centimetres


def test_it_maps_mixamo_bones_to_every_body_part():
    take = motionlib.read(shared_fbx("flair.fbx"))
    parts = motionlib.canonical_joints(take)
    assert parts["mixamorig:Hips"] == "root"
    assert parts["mixamorig:LeftForeArm"] == "left_elbow"
    assert set(parts.values()) == set(motionlib.CANONICAL_PARTS)


def test_it_reads_each_armature_as_its_own_take(made_fbx):
    takes = read_fbx_all(made_fbx / "two_armatures.fbx")
    assert sorted(t.animation for t in takes) == ["Breakdance|Scene", "Flair|Scene"]
    assert all(t.name == f"two_armatures#{t.animation}" for t in takes)


def test_it_reads_each_action_as_its_own_take(made_fbx):
    takes = read_fbx_all(made_fbx / "two_actions.fbx")
    assert {t.animation: t.n_frames for t in takes} == {"breakdance": 106, "flair": 31}


def test_it_picks_an_animation_by_name_or_number(made_fbx):
    path = made_fbx / "two_actions.fbx"
    assert motionlib.read(path, animation="flair").n_frames == 31
    assert motionlib.read(path, animation=1).animation == read_fbx_all(path)[1].animation


def test_it_lists_the_animations_when_asked_for_one_not_there(made_fbx):
    with pytest.raises(CaptureError, match=r"two_actions.fbx: no animation 'walk'; the file has "
                                           r"'breakdance', 'flair'"):
        motionlib.read(made_fbx / "two_actions.fbx", animation="walk")


def test_it_refuses_a_file_without_an_armature(made_fbx):
    with pytest.raises(CaptureError, match=r"mesh_only.fbx: no armature .* it holds mesh"):
        motionlib.read(made_fbx / "mesh_only.fbx")


def test_it_refuses_an_armature_without_animation(made_fbx):
    with pytest.raises(CaptureError, match=r"still_armature.fbx: the armature 'Armature' has no "
                                           "animation"):
        motionlib.read(made_fbx / "still_armature.fbx")


def test_it_refuses_an_armature_of_several_skeletons(made_fbx):
    with pytest.raises(CaptureError, match=r"two_roots.fbx: the armature 'Armature' has 2 root "
                                           r"bones \(Bone, Second\); a take needs one skeleton"):
        motionlib.read(made_fbx / "two_roots.fbx")


def test_it_refuses_a_truncated_file(tmp_path):
    data = shared_fbx("flair.fbx").read_bytes()
    path = tmp_path / "cut.fbx"
    path.write_bytes(data[: len(data) // 2])
    with pytest.raises(CaptureError, match=r"cut.fbx: Blender's FBX importer could not read the "
                                           r"file \(corrupt or truncated\?\)") as error:
        motionlib.read(path)
    # Blender names the file by its full path; the message keeps only its name (a server
    # stores originals in folders its users have no business seeing).
    assert str(tmp_path) not in str(error.value)
    assert "'cut.fbx'" in str(error.value)


def test_it_calls_a_binary_fbx_cut_short_in_its_header_truncated_not_ascii(tmp_path):
    path = tmp_path / "stub.fbx"
    path.write_bytes(shared_fbx("flair.fbx").read_bytes()[:27])
    with pytest.raises(CaptureError) as error:
        motionlib.read(path)
    assert str(error.value) == (
        "stub.fbx: Blender's FBX importer could not read the file (corrupt or truncated?): the "
        "start of the file does not read as binary FBX")


def test_it_refuses_an_ascii_fbx_with_what_to_do(tmp_path):
    path = tmp_path / "ascii.fbx"
    path.write_text("; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n}\n")
    with pytest.raises(CaptureError, match="ascii.fbx: ASCII FBX is not supported .* binary FBX"):
        motionlib.read(path)


def test_it_refuses_a_file_that_is_not_fbx_without_starting_blender(tmp_path):
    path = tmp_path / "notes.fbx"
    path.write_text("not a take")
    fresh = blender.Blender()
    with pytest.raises(CaptureError, match="notes.fbx: not an FBX file"):
        read_fbx_all(path, blender=fresh)
    assert fresh.proc is None


def test_it_stops_blender_past_the_time_limit_and_reads_the_next_file():
    path = shared_fbx("samba_dancing.fbx")
    own = blender.Blender()
    own.start()
    try:
        with pytest.raises(CaptureError, match=r"samba_dancing.fbx: Blender did not finish "
                                               r"reading the FBX within 0.05 s"):
            read_fbx_all(path, blender=own, timeout=0.05)
        assert not own.alive()
        assert read_fbx_all(shared_fbx("flair.fbx"), blender=own)[0].n_frames == 31
    finally:
        own.stop()


def test_it_survives_blender_dying_mid_file():
    path = shared_fbx("samba_dancing.fbx")
    own = blender.Blender(retry_deaths=0)  # the death as told (test_blender_retries_a_death)
    own.start()
    doomed = own.pid
    killer = threading.Timer(0.3, lambda: os.kill(doomed, 9))
    killer.start()
    try:
        with pytest.raises(CaptureError, match=r"samba_dancing.fbx: Blender was killed by signal "
                                               r"SIGKILL while reading the FBX"):
            read_fbx_all(path, blender=own)
        assert read_fbx_all(shared_fbx("flair.fbx"), blender=own)[0].n_frames == 31
        assert own.pid != doomed
    finally:
        killer.cancel()
        own.stop()


def test_it_keeps_one_blender_for_many_files():
    own = blender.Blender()
    try:
        read_fbx_all(shared_fbx("flair.fbx"), blender=own)
        pid = own.pid
        read_fbx_all(shared_fbx("breakdance_1990.fbx"), blender=own)
        assert own.pid == pid
    finally:
        own.stop()


def test_it_never_imports_blender_into_the_reading_process():
    motionlib.read(shared_fbx("flair.fbx"))
    assert "bpy" not in sys.modules


def test_it_works_without_blender_until_an_fbx_is_read(tmp_path):
    script = (
        "import sys, motionlib, motionlib.io.fbx, motionlib.io.export\n"
        "from motionlib.io import blender\n"
        "assert 'bpy' not in sys.modules and blender._shared is None\n"
        f"print(motionlib.read({str(shared_bvh_13_29())!r}).n_frames)\n"
        f"motionlib.read({str(shared_fbx('flair.fbx'))!r})\n"
    )
    env = {**os.environ, "MOTIONLIB_BLENDER_PYTHON": str(tmp_path / "no-python")}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                          env=env)
    assert done.stdout == "4593\n"
    assert done.stderr.strip().splitlines()[-1] == (
        f"motionlib.io.blender.BlenderUnavailable: flair.fbx: MOTIONLIB_BLENDER_PYTHON="
        f"{tmp_path / 'no-python'}: no such file")
