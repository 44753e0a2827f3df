"""Exported clips come out human-sized, in metres, with exactly ``stop - start`` frames from the
first frame of their timeline, as Blender's own importers and the Khronos glTF validator see
them (not motionlib's reader)."""

import json
import subprocess
from pathlib import Path

import pytest

import motionlib
from motionlib.io.blender import blender_python
from motionlib.io.export import write_clip
from tests.fbx.files import SHARED_DATA, shared_bvh_13_29, shared_fbx

FACTS = Path(__file__).resolve().parents[1] / "fbx" / "blender_facts.py"
VALIDATE = Path(__file__).resolve().parents[1] / "fbx" / "gltf_validate.cjs"
FRONTEND = Path(__file__).resolve().parents[2] / "frontend"
# CMU subject 13 and the Mixamo dancer, head joint to toe, standing: a person's height.
PERSON = (1.2, 2.0)


def blender_facts(path):
    done = subprocess.run([blender_python(), "-I", str(FACTS), str(path)], capture_output=True,
                          text=True, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    return json.loads(done.stdout.strip().splitlines()[-1])


def validate(path):
    if not (FRONTEND / "node_modules" / "gltf-validator").is_dir():
        pytest.skip("the glTF validator is not installed (cd frontend && npm ci)")
    done = subprocess.run(["node", str(VALIDATE), str(FRONTEND), str(path)], capture_output=True,
                          text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    report = json.loads(done.stdout)
    errors = [m for m in report["issues"]["messages"] if m["severity"] == 0]
    assert report["issues"]["numErrors"] == 0, errors
    return report


def amc_13_29():
    amc = SHARED_DATA / "cmu" / "amc" / "13_29.amc"
    if not amc.is_file():
        pytest.skip(f"real CMU capture {amc} is not available")
    return motionlib.read(amc, asf=SHARED_DATA / "cmu" / "asf" / "13.asf")


def assert_fbx_clip(path, n_frames):
    facts = blender_facts(path)
    assert (facts["first_key"], facts["last_key"], facts["keys"]) == (1.0, n_frames, n_frames)
    assert PERSON[0] < facts["height"] < PERSON[1], facts["height"]


def assert_glb_clip(path, fps, n_frames):
    report = validate(path)
    assert report["info"]["animationCount"] == 1
    facts = blender_facts(path)
    assert facts["first_key"] == 0.0
    assert facts["keys"] == n_frames
    assert facts["last_key"] == pytest.approx((n_frames - 1) / fps * 24, abs=1e-3)  # 24 fps scene
    assert PERSON[0] < facts["height"] < PERSON[1], facts["height"]


@pytest.mark.slow
def test_it_writes_a_cmu_bvh_clip_as_a_person_sized_fbx_from_frame_one(tmp_path):
    take = motionlib.read(shared_bvh_13_29())
    write_clip(take, tmp_path / "clip.fbx", format="fbx", start=120, stop=480)
    assert_fbx_clip(tmp_path / "clip.fbx", 360)


@pytest.mark.slow
def test_it_writes_a_cmu_amc_clip_as_a_person_sized_fbx_from_frame_one(tmp_path):
    write_clip(amc_13_29(), tmp_path / "clip.fbx", format="fbx", start=0, stop=240)
    assert_fbx_clip(tmp_path / "clip.fbx", 240)


@pytest.mark.slow
def test_it_writes_a_cmu_amc_clip_as_a_valid_person_sized_glb(tmp_path):
    take = amc_13_29()
    write_clip(take, tmp_path / "clip.glb", format="glb", start=600, stop=840)
    assert_glb_clip(tmp_path / "clip.glb", take.fps, 240)


@pytest.mark.slow
def test_it_rescales_an_fbx_whose_declared_unit_makes_a_giant(tmp_path):
    original = shared_fbx("13_29_blender.fbx")  # a CMU BVH written at Blender's scale 1: 27 m
    take = motionlib.read(original)
    write_clip(take, tmp_path / "clip.fbx", format="fbx", start=600, stop=720, original=original)
    assert_fbx_clip(tmp_path / "clip.fbx", 120)
    write_clip(take, tmp_path / "clip.glb", format="glb", start=600, stop=720, original=original)
    assert_glb_clip(tmp_path / "clip.glb", take.fps, 120)


@pytest.mark.slow
def test_it_starts_a_mixamo_clip_on_the_first_frame_of_the_timeline(tmp_path):
    original = shared_fbx("samba_dancing.fbx")
    take = motionlib.read(original)
    write_clip(take, tmp_path / "clip.fbx", format="fbx", start=74, stop=200, original=original)
    assert_fbx_clip(tmp_path / "clip.fbx", 126)
    write_clip(take, tmp_path / "clip.glb", format="glb", start=74, stop=200, original=original)
    assert_glb_clip(tmp_path / "clip.glb", take.fps, 126)
