"""What the service admits: captures beyond the input limits fail ingest with the reason,
odd names and out-of-range numbers get a 400 or are read, never a 500 (issue 11, items 5,
11 and 12)."""

import re

from django.test import override_settings

from tests.segmentation.base import BaseTestCase, synthetic_bvh

TWO_JOINTS = (
    "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n"
    "  CHANNELS 6 Xposition Yposition Zposition Zrotation Yrotation Xrotation\n"
    "  JOINT Head\n  {\n    OFFSET 0 1 0\n    CHANNELS 3 Zrotation Yrotation Xrotation\n"
    "    End Site\n    {\n      OFFSET 0 1 0\n    }\n  }\n}\nMOTION\n"
)  # MOTION is line 16


def two_joint_bvh(n_frames=3, frame_time="0.0083333", offset="0 1 0"):
    text = TWO_JOINTS.replace("OFFSET 0 1 0\n    CHANNELS", f"OFFSET {offset}\n    CHANNELS")
    rows = "".join(f"0 {90 + f} 0 0 {f} 0 0 {f} 0\n" for f in range(n_frames))
    return (text + f"Frames: {n_frames}\nFrame Time: {frame_time}\n" + rows).encode()


class IngestLimitsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def ingest_upload(self, content, name="take.bvh"):
        r = self.upload(content, name=name)
        self.assertEqual(r.status_code, 201, r.content)
        return self.ingest(r.json()["id"])

    def test_it_fails_a_take_without_frames_with_the_reason(self):
        capture = self.ingest_upload(two_joint_bvh(n_frames=0))
        self.assertEqual(capture.status, "failed")
        self.assertEqual(capture.error, "take.bvh:17: the take has 0 frames; a capture needs at "
                                        "least 2")

    def test_it_fails_a_take_beyond_the_joint_limit_in_the_settings(self):
        with override_settings(CUTROOM_MAX_JOINTS=1):
            capture = self.ingest_upload(two_joint_bvh())
        self.assertEqual(capture.status, "failed")
        self.assertEqual(capture.error, "take.bvh:6: more than 1 joints (the limit); joint Head "
                                        "is one too many")

    def test_it_fails_a_take_beyond_the_frame_limit_in_the_settings(self):
        with override_settings(CUTROOM_MAX_FRAMES=2):
            capture = self.ingest_upload(two_joint_bvh(n_frames=3))
        self.assertEqual(capture.error, "take.bvh:17: 3 frames is more than the limit of 2")

    def test_it_fails_an_absurd_frame_rate_and_serves_the_capture(self):
        capture = self.ingest_upload(two_joint_bvh(frame_time="1e-300"))
        self.assertEqual(capture.status, "failed")
        self.assertRegex(capture.error, r"^take\.bvh:18: frame time '1e-300' is outside")
        self.assertEqual(self.client.get(f"/api/captures/{capture.pk}/").status_code, 200)

    def test_it_fails_a_huge_offset_and_serves_the_capture(self):
        capture = self.ingest_upload(two_joint_bvh(offset="0 1e300 0"))
        self.assertEqual(capture.status, "failed")
        self.assertRegex(capture.error, r"^take\.bvh:8: OFFSET of Head is '1e300', beyond")
        r = self.client.get(f"/api/captures/{capture.pk}/")
        self.assertEqual(r.status_code, 200)
        self.assertEqual(self.client.get("/api/captures/").status_code, 200)

    def test_it_reads_a_file_whose_name_has_no_word_characters(self):
        capture = self.ingest_upload(two_joint_bvh(), name="%%%.bvh")
        self.assertEqual(capture.status, "ready", capture.error)
        self.assertEqual(capture.name, "%%%.bvh")

    def test_it_reads_a_file_whose_name_is_over_255_utf8_bytes(self):
        name = "ü" * 150 + ".bvh"  # 154 characters, 304 bytes
        capture = self.ingest_upload(two_joint_bvh(), name=name)
        self.assertEqual((capture.status, capture.name), ("ready", name), capture.error)

    def test_it_reads_a_file_whose_name_is_longer_than_255_characters(self):
        capture = self.ingest_upload(two_joint_bvh(), name="ж" * 300 + ".bvh")
        self.assertEqual(capture.status, "ready", capture.error)
        # Django keeps the first 251 characters and the extension.
        self.assertEqual(capture.name, "ж" * 251 + ".bvh")

    def test_its_frames_answers_carry_a_bounded_number_of_joint_positions(self):
        capture = self.ingest_upload(synthetic_bvh(seed=3, n_segments=3))
        n_joints = capture.n_joints
        with override_settings(CUTROOM_JOINT_FRAMES_PER_REQUEST=10 * n_joints):
            r = self.client.get(f"/api/captures/{capture.pk}/frames/?start=5&stop=400")
        body = r.json()
        self.assertEqual((body["start"], body["stop"], body["n_frames"]), (5, 15, 10))


class AdmittedLimitsTestCase(BaseTestCase):
    def test_it_tells_the_pages_how_many_joints_it_admits(self):
        self.login(self.bob)
        self.assertEqual(self.client.get("/api/me/").json()["limits"], {"max_joints": 1000})
        with override_settings(CUTROOM_MAX_JOINTS=40):
            self.assertEqual(self.client.get("/api/me/").json()["limits"], {"max_joints": 40})


class OutOfRangeNumbersTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.bob)

    def test_it_refuses_a_project_filter_beyond_the_database_integer_range(self):
        for value in ("99999999999999999999", "-99999999999999999999", "9" * 5000):
            r = self.client.get(f"/api/captures/?project={value}")
            self.assertEqual(r.status_code, 400, value[:30])
            self.assertLess(len(r.content), 500)

    def test_it_refuses_library_filters_beyond_the_database_integer_range(self):
        r = self.client.get("/api/segments/?capture=99999999999999999999")
        self.assertEqual(r.status_code, 400)
        self.assertIn("capture: must be between 1 and 9223372036854775807", r.json()["detail"])

    def test_it_refuses_a_non_finite_number_filter(self):
        for value in ("nan", "inf", "1e999"):
            r = self.client.get(f"/api/segments/?min_duration={value}")
            self.assertEqual(r.status_code, 400, value)

    def test_it_refuses_an_upload_to_a_project_beyond_the_integer_range(self):
        r = self.upload(two_joint_bvh(), project=type("P", (), {"pk": 10**20})())
        self.assertEqual(r.status_code, 400)


def test_stored_names_are_safe_file_names():
    from segmentation.services.captures import stored_name

    assert stored_name("13_29.bvh") == "13_29.bvh"
    assert stored_name("%%%.BVH") == "capture.bvh"
    assert stored_name("../../etc/x.amc") == "x.amc"
    long = stored_name("ü" * 150 + ".bvh")
    assert len(long.encode()) <= 104 and long.endswith(".bvh")
    assert re.fullmatch(r"[\w-]+\.bvh", stored_name("a b\x00c.bvh"))


def test_the_import_command_checks_files_under_the_same_limits(tmp_path):
    import pytest

    from motionlib import CaptureError
    from segmentation.services.importing import check_readable

    path = tmp_path / "empty.bvh"
    path.write_bytes(two_joint_bvh(n_frames=0))
    with pytest.raises(CaptureError, match=r"empty\.bvh:17: the take has 0 frames"):
        check_readable(path)
