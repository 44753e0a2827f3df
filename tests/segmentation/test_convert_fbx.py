"""FBX uploads: the convert job (Blender, in its own process) then the usual ingest, run
in-process by calling the task functions; the integration tests run them in real workers."""

import numpy as np
import pytest
from django.core.files.uploadedfile import SimpleUploadedFile
from django.test import override_settings

import motionlib
from segmentation import services, tasks
from segmentation.files.storage import read_take
from segmentation.models import Capture, DetectionRun
from tests.fbx.files import shared_fbx
from tests.segmentation.base import BaseTestCase, synthetic_bvh


@pytest.fixture(autouse=True)
def _files(request, made_fbx):
    request.cls.made = made_fbx


class FbxUploadsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def upload_file(self, path, name=None):
        response = self.upload(path.read_bytes(), name=name or path.name)
        self.assertEqual(response.status_code, 201, response.content)
        return response.json()["id"]

    def convert_and_ingest(self, capture_id):
        """The convert job, then every ingest and detection it queued."""
        tasks.convert(capture_id)
        for capture in Capture.objects.filter(status="queued", format="fbx"):
            tasks.ingest(capture.pk)
        for run in DetectionRun.objects.filter(status="queued"):
            tasks.detect(run.pk)
        return Capture.objects.get(pk=capture_id)


class ConvertTestCase(FbxUploadsTestCase):
    def test_it_converts_a_mixamo_fbx_and_proposes_cuts(self):
        capture = self.convert_and_ingest(self.upload_file(shared_fbx("samba_dancing.fbx")))
        self.assertEqual(capture.status, "ready", capture.error)
        self.assertEqual((capture.format, capture.fps, capture.n_frames, capture.n_joints),
                         ("fbx", 30.0, 595, 65))
        self.assertEqual(capture.name, "samba_dancing.fbx")
        self.assertEqual(DetectionRun.objects.get(capture=capture).status, "ready")

    def test_it_makes_one_capture_per_animation_sharing_one_original(self):
        first = self.convert_and_ingest(self.upload_file(self.made / "two_actions.fbx"))
        captures = {c.name: c for c in Capture.objects.filter(project=self.project)}
        self.assertEqual(sorted(captures), ["two_actions.fbx#breakdance", "two_actions.fbx#flair"])
        other = captures["two_actions.fbx#flair"]
        self.assertEqual((first.name, first.n_frames), ("two_actions.fbx#breakdance", 106))
        self.assertEqual((other.status, other.n_frames, other.source_id), ("ready", 31, first.pk))
        self.assertEqual(other.original.name, first.original.name)

    def test_every_animation_reads_back_as_blenders_read_of_the_file(self):
        path = self.made / "two_actions.fbx"
        self.convert_and_ingest(self.upload_file(path))
        for capture in Capture.objects.filter(project=self.project):
            stored = read_take(capture)
            blender = motionlib.read(path, animation=capture.animation)
            np.testing.assert_array_equal(stored.channels, blender.channels)
            self.assertEqual((stored.skeleton.names, stored.skeleton.channels, stored.fps),
                             (blender.skeleton.names, blender.skeleton.channels, blender.fps))
            np.testing.assert_array_equal(stored.skeleton.offsets, blender.skeleton.offsets)
            np.testing.assert_array_equal(stored.skeleton.parents, blender.skeleton.parents)
            self.assertEqual((stored.frame_time, stored.rest_pose_frame, stored.animation),
                             (blender.frame_time, blender.rest_pose_frame, blender.animation))

    def test_a_converted_take_is_read_from_its_stored_take_not_from_the_original(self):
        capture = self.convert_and_ingest(self.upload_file(shared_fbx("flair.fbx")))
        converted = read_take(capture)
        # Were the original read again (by Blender), this would fail: it is no FBX any more.
        with open(capture.original.path, "wb") as handle:
            handle.write(b"not an FBX")
        np.testing.assert_array_equal(read_take(capture).channels, converted.channels)

    def test_it_converts_a_file_again_without_duplicating_its_animations(self):
        capture_id = self.upload_file(self.made / "two_actions.fbx")
        self.convert_and_ingest(capture_id)
        Capture.objects.filter(pk=capture_id).update(status="queued", converted="")
        self.convert_and_ingest(capture_id)
        self.assertEqual(Capture.objects.filter(project=self.project).count(), 2)

    def test_it_fails_an_fbx_without_armature_with_the_reason(self):
        capture = self.convert_and_ingest(self.upload_file(self.made / "mesh_only.fbx"))
        self.assertEqual(capture.status, "failed")
        self.assertIn("mesh_only.fbx: no armature (skeleton) in the file", capture.error)

    def test_it_fails_an_ascii_fbx_saying_to_export_binary(self):
        path = self.made / "ascii.fbx"
        path.write_text("; FBX 7.4.0 project file\nFBXHeaderExtension:  {\n}\n")
        capture = self.convert_and_ingest(self.upload_file(path))
        self.assertEqual(capture.status, "failed")
        self.assertIn("ASCII FBX is not supported", capture.error)
        with capture.original.open("rb") as handle:
            self.assertEqual(handle.read(), path.read_bytes())

    def test_it_fails_a_truncated_fbx_and_keeps_the_original(self):
        data = shared_fbx("flair.fbx").read_bytes()[:50_000]
        capture_id = self.upload(data, name="cut.fbx").json()["id"]
        capture = self.convert_and_ingest(capture_id)
        self.assertEqual(capture.status, "failed")
        self.assertRegex(capture.error, r"^cut\.fbx: Blender's FBX importer could not read")
        response = self.client.get(f"/api/captures/{capture_id}/")
        self.assertEqual((response.status_code, response.json()["status"]), (200, "failed"))

    def test_it_queues_an_fbx_upload_for_conversion_not_ingest(self):
        capture = Capture.objects.get(pk=self.upload_file(shared_fbx("flair.fbx")))
        self.assertTrue(capture.needs_conversion)
        self.assertEqual(capture.first_job(), "convert")


class AnimationsCountAsUploadsTestCase(FbxUploadsTestCase):
    """Each animation of an FBX uploaded through the API counts against the uploader's
    CUTROOM_UPLOADS_PER_HOUR, checked when the file's animations are known (conversion)."""

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=2)
    def test_a_file_with_more_animations_than_the_user_may_still_upload_fails_saying_so(self):
        self.assertEqual(self.upload(synthetic_bvh(seed=1, duration=2.0)).status_code, 201)
        capture = self.convert_and_ingest(self.upload_file(self.made / "two_actions.fbx"))
        self.assertEqual(capture.status, "failed")
        self.assertIn("this file holds 2 animations, each counted as an upload", capture.error)
        self.assertIn("(CUTROOM_UPLOADS_PER_HOUR)", capture.error)
        self.assertEqual(Capture.objects.filter(uploaded_by=self.bob).count(), 2)

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=1)
    def test_a_file_with_more_animations_than_the_hourly_limit_says_it_can_never_pass(self):
        """Issue 48, item 12: it was told "try again in 2090 s", which could never help."""
        capture = self.convert_and_ingest(self.upload_file(self.made / "two_actions.fbx"))
        self.assertEqual(capture.status, "failed")
        self.assertIn("this file holds 2 animations, each counted as an upload, and the limit "
                      "is 1 uploads per hour (CUTROOM_UPLOADS_PER_HOUR), so it can never pass",
                      capture.error)
        self.assertIn("split it into files of at most 1 animations", capture.error)
        self.assertNotIn("try again", capture.error)
        self.assertTrue(capture.error_permanent)

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=2)
    def test_a_file_within_the_limit_gives_all_its_animations_even_converted_again(self):
        capture_id = self.upload_file(self.made / "two_actions.fbx")
        self.assertEqual(self.convert_and_ingest(capture_id).status, "ready")
        Capture.objects.filter(pk=capture_id).update(status="queued", converted="", attempts=0)
        capture = self.convert_and_ingest(capture_id)
        self.assertEqual(capture.status, "ready", capture.error)
        self.assertEqual(Capture.objects.filter(project=self.project).count(), 2)

    @override_settings(CUTROOM_UPLOADS_PER_HOUR=1)
    def test_an_import_by_command_is_not_rate_limited(self):
        upload = SimpleUploadedFile("two_actions.fbx", (self.made / "two_actions.fbx").read_bytes())
        capture, _ = services.do_upload_capture(self.project, self.bob, upload)
        self.assertEqual(self.convert_and_ingest(capture.pk).status, "ready")
        self.assertEqual(Capture.objects.filter(project=self.project).count(), 2)
