"""Clips written as FBX and glTF binary (by Blender; glTF of a take without an FBX original by
motionlib.io.gltf), read back with motionlib's FBX reader and Blender's glTF importer."""

import json
import struct
import subprocess
from pathlib import Path

import numpy as np
import pytest

import motionlib
from motionlib.errors import CaptureError
from motionlib.io.blender import blender_python
from motionlib.io.export import write_clip, write_clips
from motionlib.io.fbx import read_fbx_all, read_fbx_raw
from motionlib.io.units import length_unit
from tests.fbx.files import shared_bvh_13_29, shared_fbx

GLTF_HEADS = Path(__file__).resolve().parents[1] / "fbx" / "gltf_heads.py"


def positions(take):
    return motionlib.forward_kinematics(take)


def exported_positions(take):
    """The take's joint positions in the centimetres an exported clip reads back in."""
    return positions(take) * length_unit(take).metres * 100.0


def glb_json(path):
    """The JSON chunk of a glTF binary file (header: magic, version, length; then chunks)."""
    data = path.read_bytes()
    magic, version, length = struct.unpack_from("<4sII", data)
    assert (magic, version, length) == (b"glTF", 2, len(data))
    chunk_length, chunk_type = struct.unpack_from("<I4s", data, 12)
    assert chunk_type == b"JSON"
    return json.loads(data[20:20 + chunk_length])


@pytest.mark.slow
def test_it_cuts_an_fbx_clip_that_reads_back_as_the_trimmed_frames(tmp_path):
    original = shared_fbx("13_29_blender.fbx")
    take = motionlib.read(original)
    write_clip(take, tmp_path / "clip.fbx", format="fbx", start=600, stop=1800,
               original=original)
    [clip] = read_fbx_all(tmp_path / "clip.fbx")
    assert (clip.n_frames, clip.fps) == (1200, take.fps)
    assert clip.skeleton.names == take.skeleton.names
    error = np.abs(positions(clip) - exported_positions(take)[600:1800]).max()
    assert error < 1e-4 * motionlib.skeleton_height(clip)


def test_it_keeps_the_original_armature_of_an_fbx(tmp_path):
    original = shared_fbx("flair.fbx")
    take = motionlib.read(original)
    write_clip(take, tmp_path / "clip.fbx", format="fbx", start=5, stop=25, original=original)
    _, before = read_fbx_raw(original)
    reply, after = read_fbx_raw(tmp_path / "clip.fbx")
    assert reply["animations"][0]["bones"][0] == "mixamorig:Hips"
    np.testing.assert_allclose(after["a0_rest"], before["a0_rest"], atol=1e-4)  # float32
    clip = motionlib.read(tmp_path / "clip.fbx")
    assert clip.n_frames == 20
    np.testing.assert_allclose(positions(clip), positions(take)[5:25], atol=2e-2)  # cm


def test_it_writes_a_bvh_take_as_an_fbx_with_its_joints_and_motion(tmp_path):
    take = motionlib.read(shared_bvh_13_29())
    write_clip(take, tmp_path / "clip.fbx", format="fbx", start=120, stop=480)
    clip = motionlib.read(tmp_path / "clip.fbx")
    assert (clip.n_frames, clip.fps) == (360, 120.0)
    columns = [clip.skeleton.names.index(name) for name in take.skeleton.names]
    error = np.abs(positions(clip)[:, columns] - exported_positions(take)[120:480]).max()
    assert error < 1e-4 * motionlib.skeleton_height(clip)


def test_it_writes_several_clips_of_an_fbx_in_one_go(tmp_path):
    original = shared_fbx("breakdance_1990.fbx")
    take = motionlib.read(original)
    write_clips(take, [(0, 30, tmp_path / "a.fbx"), (50, 106, tmp_path / "b.fbx")],
                format="fbx", original=original)
    assert [motionlib.read(tmp_path / n).n_frames for n in ("a.fbx", "b.fbx")] == [30, 56]


def test_it_writes_a_glb_with_the_skeleton_and_one_animation(tmp_path):
    original = shared_fbx("flair.fbx")
    take = motionlib.read(original)
    write_clip(take, tmp_path / "clip.glb", format="glb", start=0, stop=20, original=original)
    gltf = glb_json(tmp_path / "clip.glb")
    joints = {gltf["nodes"][j]["name"] for j in gltf["skins"][0]["joints"]}
    assert "mixamorig:Hips" in joints and len(joints) == take.skeleton.n_joints
    [animation] = gltf["animations"]
    times = gltf["accessors"][animation["samplers"][0]["input"]]
    assert times["count"] == 20
    assert (times["min"][0], times["max"][0]) == (0.0, pytest.approx(19 / 30.0, abs=1e-4))


def test_it_writes_a_bvh_take_as_a_glb(tmp_path):
    take = motionlib.read(shared_bvh_13_29())
    write_clip(take, tmp_path / "clip.glb", format="glb", start=0, stop=240)
    gltf = glb_json(tmp_path / "clip.glb")
    names = {node["name"] for node in gltf["nodes"]}
    assert set(take.skeleton.names) <= names
    assert gltf["accessors"][gltf["animations"][0]["samplers"][0]["input"]]["count"] == 240


def gltf_positions(path, fps, frames):
    """Joint positions (cm) of a .glb on ``frames``, as Blender's glTF importer poses them."""
    done = subprocess.run([blender_python(), "-I", str(GLTF_HEADS), str(path), str(fps),
                           *map(str, frames)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    body = json.loads(done.stdout.strip().splitlines()[-1])
    return body["names"], np.array(body["heads"]) * 100.0


@pytest.mark.parametrize("source", ["samba_dancing.fbx", "13_29.bvh"])
def test_it_writes_a_glb_that_poses_the_clip_as_the_take(tmp_path, source):
    path = shared_bvh_13_29() if source.endswith(".bvh") else shared_fbx(source)
    take = motionlib.read(path)
    original = path if source.endswith(".fbx") else None
    write_clip(take, tmp_path / "clip.glb", format="glb", start=50, stop=350, original=original)
    frames = [0, 101, 237, 299]
    names, heads = gltf_positions(tmp_path / "clip.glb", take.fps, frames)
    columns = [take.skeleton.names.index(name) for name in names]
    expected = exported_positions(take)[[50 + f for f in frames]][:, columns]
    height = motionlib.skeleton_height(take) * length_unit(take).metres * 100.0
    assert np.abs(heads - expected).max() < 1e-4 * height


def test_it_refuses_an_unknown_format(tmp_path):
    take = motionlib.read(shared_fbx("flair.fbx"))
    with pytest.raises(CaptureError, match="unknown export format 'obj'; expected one of bvh, "
                                           "fbx, glb"):
        write_clip(take, tmp_path / "clip.obj", format="obj")
