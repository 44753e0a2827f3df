"""glTF binary clips of takes without a mesh, written without Blender (motionlib.io.gltf), as
the Khronos glTF validator and Blender's own glTF importer read them."""

import numpy as np
import pytest

import motionlib
from motionlib.io.export import write_clip, write_clips
from motionlib.io.gltf import glb_bytes
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


def test_its_bytes_are_a_function_of_the_clip():
    """The same clip gives the same file: a library's archive exports to the same bytes."""
    take = motionlib.read(shared_bvh_13_29()).slice(0, 50)
    assert glb_bytes(take, metres=0.05) == glb_bytes(take, metres=0.05)
