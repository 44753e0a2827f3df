"""glTF binary clips of takes without a mesh, written without Blender (motionlib.io.gltf), as
the Khronos glTF validator and Blender's own glTF importer read them."""

import json
import struct

import numpy as np
import pytest

import motionlib
from motionlib.io.export import write_clip, write_clips
from motionlib.io.units import length_unit
from tests.fbx.files import shared_bvh_13_29
from tests.motionlib.test_io_export import glb_json, gltf_positions
from tests.motionlib.test_io_export_size import amc_13_29, validate


class NoBlender:
    """Stands where the Blender child would: any request to it fails the test."""

    def request(self, *args, **kwargs):
        raise AssertionError("a clip without a mesh went to Blender")


def fk_cm(take, frames):
    """The take's joint positions on ``frames`` in the centimetres of an exported clip."""
    return motionlib.forward_kinematics(take)[frames] * length_unit(take).metres * 100.0


def test_it_writes_a_bvh_clip_as_glb_without_blender(tmp_path):
    take = motionlib.read(shared_bvh_13_29())
    write_clips(take, [(0, 120, tmp_path / "a.glb"), (300, 301, tmp_path / "b.glb")],
                format="glb", blender=NoBlender())
    for name, frames in (("a.glb", 120), ("b.glb", 1)):
        gltf = glb_json(tmp_path / name)
        times = gltf["accessors"][gltf["animations"][0]["samplers"][0]["input"]]
        assert times["count"] == frames
        assert (times["min"][0], times["max"][0]) == (0.0, pytest.approx((frames - 1) / 120))


def test_it_names_the_joints_and_keeps_their_rest_offsets_in_metres(tmp_path):
    take = motionlib.read(shared_bvh_13_29())
    write_clip(take, tmp_path / "clip.glb", format="glb", start=10, stop=20, blender=NoBlender())
    gltf = glb_json(tmp_path / "clip.glb")
    sk, metres = take.skeleton, length_unit(take).metres
    joints = [gltf["nodes"][j] for j in gltf["skins"][0]["joints"]]
    assert [node["name"] for node in joints] == list(sk.names)
    np.testing.assert_allclose([node["translation"] for node in joints], sk.offsets * metres,
                               atol=1e-6)
    [root] = gltf["scenes"][0]["nodes"]
    assert gltf["nodes"][root]["name"] == take.name  # the armature, as Blender names it
    [animation] = gltf["animations"]
    moved = {(c["target"]["node"], c["target"]["path"]) for c in animation["channels"]}
    assert {(j, "rotation") for j in range(sk.n_joints)} <= moved
    assert (0, "translation") in moved and (1, "translation") not in moved


def test_it_writes_a_glb_the_khronos_validator_passes(tmp_path):
    take = motionlib.read(shared_bvh_13_29())
    write_clip(take, tmp_path / "bvh.glb", format="glb", start=600, stop=840,
               blender=NoBlender())
    report = validate(tmp_path / "bvh.glb")
    assert report["info"]["animationCount"] == 1
    assert report["issues"]["numWarnings"] == 0


def test_it_writes_an_amc_clip_the_khronos_validator_passes(tmp_path):
    take = amc_13_29()
    write_clip(take, tmp_path / "amc.glb", format="glb", start=0, stop=300, blender=NoBlender())
    assert validate(tmp_path / "amc.glb")["issues"]["numWarnings"] == 0


@pytest.mark.parametrize("source", ["13_29.bvh", "13_29.amc"])
def test_blenders_importer_poses_the_glb_as_motionlibs_kinematics(tmp_path, source):
    """Blender's glTF importer, a reader independent of this writer, puts every joint where
    forward kinematics of the take puts it, on frames across the clip."""
    take = motionlib.read(shared_bvh_13_29()) if source.endswith(".bvh") else amc_13_29()
    write_clip(take, tmp_path / "clip.glb", format="glb", start=400, stop=700,
               blender=NoBlender())
    frames = [0, 1, 150, 299]
    names, heads = gltf_positions(tmp_path / "clip.glb", take.fps, frames)
    columns = [take.skeleton.names.index(name) for name in names]
    expected = fk_cm(take, [400 + f for f in frames])[:, columns]
    height = motionlib.skeleton_height(take) * length_unit(take).metres * 100.0
    assert np.abs(heads - expected).max() < 1e-4 * height


def turning_bvh(path, frames=73):
    """A two-joint BVH whose root turns a full circle about Y, 5 degrees a frame: its
    rotation crosses 180 degrees, where a quaternion's sign flips unless it is kept."""
    lines = ["HIERARCHY", "ROOT Hips", "{", "OFFSET 0 0 0",
             "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation",
             "JOINT Chest", "{", "OFFSET 0 10 0", "CHANNELS 3 Zrotation Xrotation Yrotation",
             "End Site", "{", "OFFSET 0 10 0", "}", "}", "}",
             "MOTION", f"Frames: {frames}", "Frame Time: 0.0333333"]
    lines += [f"0 90 0 0 0 {5.0 * f} 0 0 0" for f in range(frames)]
    path.write_text("\n".join(lines) + "\n")
    return motionlib.read(path)


def rotation_keys(data):
    """Each rotation channel's keys, (n_frames, 4) as (x, y, z, w), of a .glb's bytes."""
    length, = struct.unpack_from("<I", data, 12)
    gltf, binary = json.loads(data[20:20 + length]), data[28 + length:]
    [animation] = gltf["animations"]
    for sampler, channel in zip(animation["samplers"], animation["channels"], strict=True):
        if channel["target"]["path"] == "rotation":
            accessor = gltf["accessors"][sampler["output"]]
            offset = gltf["bufferViews"][accessor["bufferView"]]["byteOffset"]
            keys = np.frombuffer(binary, "<f4", accessor["count"] * 4, offset)
            yield keys.reshape(-1, 4).astype(np.float64)


def test_it_keys_each_joints_rotation_the_short_way_between_frames(tmp_path):
    """Consecutive quaternions of a joint lie in one hemisphere: a reader's LINEAR (or slerp)
    interpolation between two frames turns the joint the short way, never back round."""
    take = turning_bvh(tmp_path / "turn.bvh")
    write_clip(take, tmp_path / "turn.glb", format="glb", blender=NoBlender())
    [root, chest] = rotation_keys((tmp_path / "turn.glb").read_bytes())
    for keys in (root, chest):
        np.testing.assert_allclose(np.linalg.norm(keys, axis=1), 1.0, atol=1e-6)
        assert (np.sum(keys[1:] * keys[:-1], axis=1) > 0).all()
    half = np.radians(2.5 * np.arange(73))  # the root's half angle about Y, every frame
    np.testing.assert_allclose(np.abs(root[:, [1, 3]]),
                               np.abs(np.stack([np.sin(half), np.cos(half)], 1)), atol=1e-5)
    assert validate(tmp_path / "turn.glb")["issues"]["numErrors"] == 0
