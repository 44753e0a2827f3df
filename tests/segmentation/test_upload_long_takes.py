"""Hour-long takes upload with the shipped limits, streamed to a temporary file as they
arrive and stored unchanged."""

import hashlib
from unittest import mock

import pytest
from django.core.files.uploadedfile import TemporaryUploadedFile

from segmentation import services
from segmentation.models import Capture
from tests.segmentation.base import SHARED_DATA, BaseTestCase

REAL_TAKE = SHARED_DATA / "cmu" / "bvh" / "13_29.bvh"
HOUR_AT_120_FPS = 432_000


def repeated_bvh(n_frames):
    """A BVH of the real CMU take 13_29 (120 fps) with its motion repeated to ``n_frames``."""
    text = REAL_TAKE.read_bytes()
    header, motion = text.split(b"Frame Time:", 1)
    frame_time, frames = motion.split(b"\n", 1)
    lines = frames.splitlines(keepends=True)
    repeats, rest = divmod(n_frames, len(lines))
    header = header.replace(header[header.index(b"Frames:"):], f"Frames: {n_frames}\n".encode())
    return b"".join([header, b"Frame Time:", frame_time, b"\n", b"".join(lines) * repeats, *lines[:rest]])


class UploadingRealTake(BaseTestCase):
    def setUp(self):
        super().setUp()
        if not REAL_TAKE.exists():
            self.skipTest(f"real CMU data not found at {REAL_TAKE}")
        self.login(self.bob)

    def upload_seen_by_the_service(self, content):
        """The response, and the uploaded file as the upload service received it."""
        seen = {}

        def spy(project, user, upload, asf=None, **options):
            seen["upload"] = upload
            seen["on_disk"] = isinstance(upload, TemporaryUploadedFile)
            return do_upload_capture(project, user, upload, asf, **options)

        do_upload_capture = services.do_upload_capture
        with mock.patch.object(services, "do_upload_capture", spy):
            response = self.upload(content, name="13_29_long.bvh")
        return response, seen


class LongTakeUploadTestCase(UploadingRealTake):
    def test_the_shipped_limit_takes_an_hour_of_a_real_take_at_120_fps(self):
        per_frame = (len(repeated_bvh(2000)) - len(repeated_bvh(1000))) / 1000
        hour = len(repeated_bvh(1000)) + per_frame * (HOUR_AT_120_FPS - 1000)
        self.assertGreater(hour, 200 * 2**20)  # the previous default refused it
        self.assertLess(hour, services.captures.max_upload_bytes())

    def test_it_streams_an_upload_to_a_temporary_file_and_stores_it_unchanged(self):
        content = repeated_bvh(20_000)  # 15 MB: past FILE_UPLOAD_MAX_MEMORY_SIZE
        response, seen = self.upload_seen_by_the_service(content)
        self.assertEqual(response.status_code, 201, response.content[:300])
        self.assertTrue(seen["on_disk"], type(seen["upload"]))
        with Capture.objects.get().original.open("rb") as handle:
            self.assertEqual(handle.read(), content)


@pytest.mark.slow
class HourLongTakeUploadTestCase(UploadingRealTake):
    def test_it_accepts_a_take_past_the_previous_limit_with_the_shipped_defaults(self):
        content = repeated_bvh(300_000)  # about 225 MB
        self.assertGreater(len(content), 200 * 2**20)
        digest = hashlib.sha256(content).hexdigest()
        response, seen = self.upload_seen_by_the_service(content)
        del content
        self.assertEqual(response.status_code, 201, response.content[:300])
        self.assertTrue(seen["on_disk"], type(seen["upload"]))
        capture = Capture.objects.get()
        stored = hashlib.sha256()
        with capture.original.open("rb") as handle:
            while chunk := handle.read(2**20):
                stored.update(chunk)
        self.assertEqual((stored.hexdigest(), capture.checksum), (digest, digest))
