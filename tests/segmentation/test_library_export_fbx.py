"""Library segments downloaded as FBX and glTF binary, one at a time and in a zip with one
manifest; a clip of an FBX capture keeps its original's armature."""

import io
import json
import zipfile

import numpy as np
import pytest

import motionlib
from motionlib.io.units import length_unit
from segmentation import tasks
from segmentation.files import storage
from segmentation.models import Capture, DetectionRun, LibrarySegment
from tests.fbx.files import shared_fbx
from tests.segmentation.base import BaseTestCase, synthetic_bvh
from tests.segmentation.test_library import submit_review


def ingested(capture_id):
    """Run the worker's jobs in-process: convert (FBX), ingest, detection."""
    capture = Capture.objects.get(pk=capture_id)
    if capture.needs_conversion:
        tasks.convert(capture_id)
    tasks.ingest(capture_id)
    for run in DetectionRun.objects.filter(capture_id=capture_id, status="queued"):
        tasks.detect(run.pk)
    capture = Capture.objects.get(pk=capture_id)
    assert capture.status == "ready", capture.error
    return capture


def read_clip(tmp_path, name, data):
    path = tmp_path / name
    path.write_bytes(data)
    return motionlib.read(path)


class ExportTestCase(BaseTestCase):
    @pytest.fixture(autouse=True)
    def _tmp(self, tmp_path):
        self.tmp = tmp_path

    def setUp(self):
        super().setUp()
        self.login(self.bob)
        content = shared_fbx("breakdance_1990.fbx").read_bytes()
        self.capture = ingested(self.upload(content, name="breakdance.fbx").json()["id"])
        submit_review(self.capture, self.bob, [40, 80], ["walk", "punch", "walk"])
        self.segments = list(LibrarySegment.objects.order_by("start"))

    def test_it_downloads_a_segment_as_fbx_cut_from_the_original(self):
        segment = self.segments[1]
        response = self.client.get(f"/api/segments/{segment.pk}/export.fbx")
        assert response.status_code == 200
        name = "breakdance_punch_40-80.fbx"
        assert response["Content-Disposition"] == f'attachment; filename="{name}"'
        clip = read_clip(self.tmp, name, response.content)
        assert clip.n_frames == 40 and clip.skeleton.names[0] == "mixamorig:Hips"

    def test_it_downloads_a_segment_as_glb(self):
        response = self.client.get(f"/api/segments/{self.segments[0].pk}/export.glb")
        assert (response.status_code, response["Content-Type"]) == (200, "model/gltf-binary")
        assert response.content[:4] == b"glTF"

    def test_it_refuses_an_export_format_it_does_not_write(self):
        response = self.client.get(f"/api/segments/{self.segments[0].pk}/export.obj")
        assert response.status_code == 400
        assert response.json()["detail"] == ("format: 'obj' is not an export format; choose one "
                                             "of bvh, fbx, glb, c3d, csv")

    def test_it_zips_every_segment_as_fbx_with_one_manifest(self):
        response = self.client.get("/api/segments/export.zip?file_format=fbx")
        assert response.status_code == 200
        archive = zipfile.ZipFile(io.BytesIO(b"".join(response.streaming_content)))
        manifest = json.loads(archive.read("manifest.json"))
        assert [(m["file"], m["format"]) for m in manifest] == [
            ("breakdance_walk_0-40.fbx", "fbx"), ("breakdance_punch_40-80.fbx", "fbx"),
            ("breakdance_walk_80-106.fbx", "fbx")]
        assert "manifest.csv" in archive.namelist()
        last = read_clip(self.tmp, "last.fbx", archive.read("breakdance_walk_80-106.fbx"))
        assert last.n_frames == 26

    def test_it_refuses_a_zip_in_an_unknown_format(self):
        response = self.client.get("/api/segments/export.zip?file_format=obj")
        assert response.status_code == 400
        assert "format: 'obj' is not an export format" in response.json()["detail"]


class BvhCaptureExportTestCase(BaseTestCase):
    @pytest.fixture(autouse=True)
    def _tmp(self, tmp_path):
        self.tmp = tmp_path

    def test_it_downloads_a_segment_of_a_bvh_capture_as_fbx(self):
        self.login(self.bob)
        capture = ingested(self.upload(synthetic_bvh(seed=3, duration=6.0)).json()["id"])
        submit_review(capture, self.bob, [240], ["walk", "punch"])
        segment = LibrarySegment.objects.get(start=240)
        response = self.client.get(f"/api/segments/{segment.pk}/export.fbx")
        assert response.status_code == 200, response.content[:300]
        clip = read_clip(self.tmp, "clip.fbx", response.content)
        assert clip.n_frames == capture.n_frames - 240
        assert response["X-Length-Unit"] == ("metre; the capture's unit taken as CMU Acclaim "
                                             "unit (inch / 0.45) (chosen by the figure's height)")
        joints = capture.skeleton["joints"]
        columns = [clip.skeleton.names.index(name) for name in joints]
        # The clip reads back in centimetres of the metres its unit makes of the capture's.
        centimetres = length_unit(storage.read_take(capture)).metres * 100.0
        stored = storage.load_npy(capture.positions)[240:] * centimetres
        moved = motionlib.forward_kinematics(clip)[:, columns]
        np.testing.assert_allclose(moved, stored,
                                   atol=1e-4 * capture.skeleton["height"] * centimetres)
