from django.test import override_settings

from segmentation.models import Capture
from tests.segmentation.base import SHARED_DATA, BaseTestCase

BVH = b"HIERARCHY\nROOT Hips\n{\n}\nMOTION\nFrames: 0\nFrame Time: 0.0083333\n"


class UploadTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def test_it_stores_the_original_unchanged_and_queues_ingest(self):
        r = self.upload(BVH, name="walk.bvh")
        self.assertEqual(r.status_code, 201)
        body = r.json()
        self.assertEqual((body["status"], body["format"], body["name"], body["duplicate"]), ("queued", "bvh", "walk.bvh", False))
        self.assertIsNone(body["skeleton"])
        capture = Capture.objects.get(pk=body["id"])
        with capture.original.open("rb") as handle:
            self.assertEqual(handle.read(), BVH)
        self.assertEqual(capture.uploaded_by, self.bob)

    def test_it_recognises_a_duplicate_in_the_same_project(self):
        first = self.upload(BVH).json()
        r = self.upload(BVH, name="again.bvh")
        self.assertEqual(r.status_code, 200)
        self.assertEqual((r.json()["id"], r.json()["duplicate"]), (first["id"], True))
        self.assertEqual(Capture.objects.count(), 1)

    def test_the_same_file_in_another_project_is_a_new_capture(self):
        self.upload(BVH)
        self.login(self.charlie)
        r = self.upload(BVH, project=self.other_project)
        self.assertEqual(r.status_code, 201)

    def test_it_refuses_a_wrong_extension(self):
        r = self.upload(b"x,y,z\n1,2,3\n", name="take.txt")
        self.assertEqual(r.status_code, 400)
        self.assertIn("'take.txt' has extension '.txt'", r.json()["detail"])
        self.assertFalse(Capture.objects.exists())

    def test_it_refuses_an_empty_file(self):
        r = self.upload(b"", name="empty.bvh")
        self.assertEqual(r.status_code, 400)
        self.assertIn("'empty.bvh' is empty (0 bytes)", r.json()["detail"])

    def test_it_refuses_amc_without_asf(self):
        r = self.upload(b":FULLY-SPECIFIED\n1\nroot 0 0 0 0 0 0\n", name="13_30.amc")
        self.assertEqual(r.status_code, 400)
        self.assertIn("upload its .asf skeleton", r.json()["asf"][0])

    def test_it_refuses_an_asf_that_is_not_one(self):
        r = self.upload(b"1\n", name="13_30.amc", asf=("13.txt", b"x"))
        self.assertEqual(r.status_code, 400)
        self.assertIn("'13.txt' is not an .asf file", r.json()["detail"])

    @override_settings(CUTROOM_MAX_UPLOAD_MB=1)
    def test_it_refuses_a_file_over_the_limit(self):
        r = self.upload(BVH + b"0 " * 700_000)
        self.assertEqual(r.status_code, 413)
        self.assertIn("the limit is 1 MB", r.json()["detail"])

    @override_settings(CUTROOM_MAX_UPLOAD_MB=1)
    def test_it_refuses_a_body_over_the_limit_before_reading_it(self):
        r = self.upload(BVH + b"0 " * 2_000_000)
        self.assertEqual(r.status_code, 413)
        self.assertIn("CUTROOM_MAX_UPLOAD_MB", r.json()["detail"])

    def test_it_refuses_a_missing_file(self):
        r = self.client.post("/api/captures/", {"project": self.project.pk}, format="multipart")
        self.assertEqual(r.status_code, 400)
        self.assertIn("file", r.json())

    def test_outsider_cannot_upload_to_the_project(self):
        self.login(self.charlie)
        r = self.upload(BVH)
        self.assertEqual(r.status_code, 404)
        self.assertFalse(Capture.objects.exists())

    def test_it_keeps_earlier_captures_when_an_upload_is_refused(self):
        self.upload(BVH)
        self.upload(b"", name="empty.bvh")
        self.upload(b"junk", name="junk.txt")
        self.assertEqual(list(Capture.objects.values_list("name", flat=True)), ["take.bvh"])

    def test_it_accepts_amc_with_its_asf(self):
        amc = SHARED_DATA / "cmu" / "amc" / "13_30.amc"
        if not amc.exists():
            self.skipTest(f"real CMU data not found at {amc}")
        asf = (SHARED_DATA / "cmu" / "asf" / "13.asf").read_bytes()
        r = self.upload(amc.read_bytes(), name="13_30.amc", asf=("13.asf", asf))
        self.assertEqual(r.status_code, 201)
        self.assertEqual(r.json()["format"], "amc")
        self.assertTrue(Capture.objects.get().asf.name.endswith("13.asf"))
