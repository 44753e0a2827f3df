"""Reference videos of a capture (issue 49, item 1): upload by reviewers and admins, real
files made by ffmpeg, the refusals each with its message, the offset, the bytes in ranges,
the quotas, deletion with the capture, and backups."""

import hashlib
import io
import tarfile
from pathlib import Path

from django.core.files.uploadedfile import SimpleUploadedFile
from django.core.management import call_command
from django.test import override_settings

from segmentation.api.common import ranges
from segmentation.models import Capture, ReferenceVideo
from tests.segmentation.base import BaseTestCase
from tests.videofiles import make_video


class VideoTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.url = f"/api/captures/{self.capture.pk}/videos/"

    def send(self, path, name=None, as_user=None):
        self.login(as_user or self.rachel)
        upload = SimpleUploadedFile(name or Path(path).name, Path(path).read_bytes())
        return self.client.post(self.url, {"file": upload}, format="multipart")

    def stored(self, video_id):
        return Path(ReferenceVideo.objects.get(pk=video_id).file.path)


class UploadTests(VideoTestCase):
    def test_it_stores_an_h264_mp4_with_what_ffprobe_read(self):
        path = make_video("h264", seconds=2.0, fps=30)
        answer = self.send(path, "camera A.mp4")
        assert answer.status_code == 201, answer.json()
        video = answer.json()
        assert (video["name"], video["container"], video["codec"]) == ("camera A.mp4", "mp4", "h264")
        assert video["duration"] == 2.0 and video["fps"] == 30.0
        assert (video["width"], video["height"]) == (160, 120)
        assert video["checksum"] == hashlib.sha256(path.read_bytes()).hexdigest()
        assert video["uploaded_by"]["username"] == "rachel" and video["offset_s"] == 0.0
        assert self.stored(video["id"]).read_bytes() == path.read_bytes()

    def test_it_stores_a_vp9_webm(self):
        answer = self.send(make_video("vp9"))
        assert answer.status_code == 201, answer.json()
        assert (answer.json()["container"], answer.json()["codec"]) == ("webm", "vp9")
        assert answer.json()["content_type"] == "video/webm"

    def test_a_capture_holds_several_videos_and_the_same_file_once(self):
        first = self.send(make_video("h264"))
        assert self.send(make_video("vp9")).status_code == 201
        again = self.send(make_video("h264"))
        assert again.status_code == 200 and again.json()["duplicate"] is True
        assert again.json()["id"] == first.json()["id"]
        listed = self.client.get(self.url).json()
        assert [v["container"] for v in listed["videos"]] == ["mp4", "webm"]
        assert listed["may_manage"] is True and listed["probes"] is True

    def test_an_admin_uploads_too(self):
        assert self.send(make_video("h264"), as_user=self.alice).status_code == 201


class RefusalTests(VideoTestCase):
    def refused(self, answer, status, *words):
        assert answer.status_code == status, answer.content
        detail = answer.json()["detail"]
        for word in words:
            assert word in detail, detail
        assert not ReferenceVideo.objects.exists()
        assert not (Path(self.settings_media()) / "videos").exists() or not any(
            p.is_file() for p in (Path(self.settings_media()) / "videos").rglob("*"))
        return detail

    def settings_media(self):
        from django.conf import settings
        return settings.MEDIA_ROOT

    def test_an_annotator_may_watch_but_not_upload(self):
        answer = self.send(make_video("h264"), as_user=self.bob)
        self.refused(answer, 403, "reviewers and admins")
        listed = self.client.get(self.url)
        assert listed.status_code == 200 and listed.json()["may_manage"] is False

    def test_an_outsider_gets_404_for_everything(self):
        video = self.send(make_video("h264")).json()
        self.login(self.charlie)
        upload = SimpleUploadedFile("x.mp4", make_video("h264").read_bytes())
        assert self.client.post(self.url, {"file": upload}, format="multipart").status_code == 404
        assert self.client.get(self.url).status_code == 404
        assert self.client.get(video["url"]).status_code == 404
        item = f"{self.url}{video['id']}/"
        assert self.client.patch(item, {"offset_s": 1}, format="json").status_code == 404
        assert self.client.delete(item).status_code == 404
        assert ReferenceVideo.objects.get().offset_s == 0.0

    def test_it_refuses_a_file_that_is_not_a_video(self):
        answer = self.send(Path(__file__), "notes.mp4")
        self.refused(answer, 400, "'notes.mp4'", "not a video")

    def test_it_refuses_hevc(self):
        self.refused(self.send(make_video("hevc"), "drone.mp4"), 400, "'drone.mp4'", "HEVC", "H.264")

    def test_it_refuses_prores_in_quicktime(self):
        self.refused(self.send(make_video("prores"), "edit.mov"), 400, "'edit.mov'", "QuickTime")

    def test_it_refuses_avi(self):
        self.refused(self.send(make_video("avi")), 400, "AVI")

    def test_it_refuses_10_bit_h264(self):
        self.refused(self.send(make_video("h264-10bit")), 400, "yuv420p10le")

    def test_it_refuses_a_truncated_mp4(self):
        path = Path(self.settings_media()).parent / "cut.mp4"
        path.parent.mkdir(parents=True, exist_ok=True)
        data = make_video("h264").read_bytes()
        path.write_bytes(data[:64] + data[-64:])
        self.refused(self.send(path), 400, "'cut.mp4' has no video stream")

    def test_it_refuses_an_empty_file(self):
        self.login(self.rachel)
        answer = self.client.post(self.url, {"file": SimpleUploadedFile("e.mp4", b"")}, format="multipart")
        self.refused(answer, 400, "'e.mp4' is empty")

    @override_settings(CUTROOM_MAX_VIDEO_MB=0)
    def test_it_refuses_a_video_over_the_size_limit(self):
        self.refused(self.send(make_video("h264"), "big.mp4"), 413, "'big.mp4'", "CUTROOM_MAX_VIDEO_MB")

    def test_it_refuses_a_body_over_the_size_limit_before_reading_it(self):
        self.login(self.rachel)
        with override_settings(CUTROOM_MAX_VIDEO_MB=1):
            answer = self.client.post(self.url, {"file": SimpleUploadedFile("big.mp4", b"\0" * (3 * 2**20))},
                                      format="multipart")
        self.refused(answer, 413, "the upload is 3.0 MB", "CUTROOM_MAX_VIDEO_MB")


class WithoutFfprobeTests(VideoTestCase):
    @override_settings(CUTROOM_FFPROBE="")
    def test_it_checks_the_container_and_leaves_the_rest_unknown(self):
        answer = self.send(make_video("h264"))
        assert answer.status_code == 201, answer.json()
        video = answer.json()
        assert (video["container"], video["codec"], video["duration"], video["fps"]) == ("mp4", "", None, None)
        assert self.client.get(self.url).json()["probes"] is False

    @override_settings(CUTROOM_FFPROBE="no-such-ffprobe")
    def test_it_still_refuses_what_is_not_mp4_or_webm(self):
        answer = self.send(make_video("avi"))
        assert answer.status_code == 400 and "AVI" in answer.json()["detail"]


class QuotaTests(VideoTestCase):
    def test_videos_count_in_the_project_and_user_quotas(self):
        size = make_video("h264", seconds=3.0).stat().st_size
        used = self.capture.stored_bytes
        with override_settings(CUTROOM_PROJECT_STORAGE_MB=(used + size - 1) / 2**20):
            answer = self.send(make_video("h264", seconds=3.0))
        assert answer.status_code == 413 and "CUTROOM_PROJECT_STORAGE_MB" in answer.json()["detail"]
        assert self.send(make_video("h264", seconds=3.0)).status_code == 201
        with override_settings(CUTROOM_USER_STORAGE_MB=(size + 10) / 2**20):
            answer = self.send(make_video("vp9"))
        assert answer.status_code == 413 and "CUTROOM_USER_STORAGE_MB" in answer.json()["detail"]

    def test_a_capture_upload_counts_the_videos_already_stored(self):
        size = make_video("h264").stat().st_size
        assert self.send(make_video("h264")).status_code == 201
        self.login(self.rachel)
        bvh = b"x" * 100
        with override_settings(CUTROOM_USER_STORAGE_MB=(size + 50) / 2**20):
            answer = self.upload(bvh, "take.bvh")
        assert answer.status_code == 413 and "your uploads" in answer.json()["detail"]


class OffsetTests(VideoTestCase):
    def setUp(self):
        super().setUp()
        self.video = self.send(make_video("h264")).json()
        self.item = f"{self.url}{self.video['id']}/"

    def test_a_reviewer_saves_the_offset(self):
        answer = self.client.patch(self.item, {"offset_s": -1.25}, format="json")
        assert answer.status_code == 200, answer.json()
        assert answer.json()["offset_s"] == -1.25
        assert answer.json()["offset_set_by"]["username"] == "rachel"
        assert ReferenceVideo.objects.get().offset_s == -1.25
        assert self.client.get(self.url).json()["videos"][0]["offset_s"] == -1.25

    def test_an_annotator_may_not_change_it(self):
        self.login(self.bob)
        answer = self.client.patch(self.item, {"offset_s": 3}, format="json")
        assert answer.status_code == 403 and "reviewers and admins" in answer.json()["detail"]
        assert self.client.delete(self.item).status_code == 403
        assert ReferenceVideo.objects.get().offset_s == 0.0

    def test_it_names_a_bad_offset(self):
        for value in ("soon", None, 1e9):
            answer = self.client.patch(self.item, {"offset_s": value}, format="json")
            assert answer.status_code == 400, value
            assert "offset_s" in answer.json(), answer.json()
        assert ReferenceVideo.objects.get().offset_s == 0.0


class RangeTests(VideoTestCase):
    def setUp(self):
        super().setUp()
        self.path = make_video("h264", seconds=3.0)
        self.data = self.path.read_bytes()
        self.video = self.send(self.path).json()

    def get(self, range_header=None, user=None):
        self.login(user or self.bob)  # every member plays it
        headers = {"HTTP_RANGE": range_header} if range_header else {}
        return self.client.get(self.video["url"], **headers)

    def test_it_answers_a_range_with_206_and_those_bytes(self):
        answer = self.get("bytes=100-199")
        assert answer.status_code == 206
        assert answer["Content-Range"] == f"bytes 100-199/{len(self.data)}"
        assert answer["Content-Type"] == "video/mp4" and answer["Accept-Ranges"] == "bytes"
        assert b"".join(answer.streaming_content) == self.data[100:200]

    def test_it_answers_the_last_bytes_and_an_open_range(self):
        assert b"".join(self.get("bytes=-10").streaming_content) == self.data[-10:]
        answer = self.get("bytes=50-")
        assert answer["Content-Length"] == str(len(self.data) - 50)
        assert b"".join(answer.streaming_content) == self.data[50:]

    def test_it_answers_an_open_range_in_bounded_parts(self):
        original = ranges.MAX_RANGE_BYTES
        ranges.MAX_RANGE_BYTES = 1000
        try:
            answer = self.get("bytes=0-")
        finally:
            ranges.MAX_RANGE_BYTES = original
        assert answer.status_code == 206
        assert answer["Content-Range"] == f"bytes 0-999/{len(self.data)}"
        assert b"".join(answer.streaming_content) == self.data[:1000]

    def test_it_answers_past_the_end_with_416(self):
        answer = self.get(f"bytes={len(self.data)}-")
        assert answer.status_code == 416 and answer["Content-Range"] == f"bytes */{len(self.data)}"

    def test_without_a_range_it_sends_the_whole_file(self):
        answer = self.get()
        assert answer.status_code == 200 and b"".join(answer.streaming_content) == self.data
        assert answer["Cache-Control"].startswith("private")

    def test_a_nonsense_range_gets_the_whole_file(self):
        answer = self.get("bytes=9-3")
        assert answer.status_code == 200 and b"".join(answer.streaming_content) == self.data


class DeletionTests(VideoTestCase):
    def test_removing_a_video_removes_its_file(self):
        video = self.send(make_video("h264")).json()
        path = self.stored(video["id"])
        with self.captureOnCommitCallbacks(execute=True):
            assert self.client.delete(f"{self.url}{video['id']}/").status_code == 204
        assert not path.exists() and not ReferenceVideo.objects.exists()

    def test_videos_go_with_their_capture(self):
        paths = [self.stored(self.send(make_video(kind)).json()["id"]) for kind in ("h264", "vp9")]
        with self.captureOnCommitCallbacks(execute=True):
            Capture.objects.get(pk=self.capture.pk).delete()
        assert not ReferenceVideo.objects.exists()
        assert not any(path.exists() for path in paths)


class BackupTests(VideoTestCase):
    def test_a_backup_holds_the_video_its_row_and_its_offset(self):
        video = self.send(make_video("h264")).json()
        self.client.patch(f"{self.url}{video['id']}/", {"offset_s": 0.5}, format="json")
        stored = ReferenceVideo.objects.get()
        backup = Path(self.settings_media_parent()) / "cutroom.tar"
        call_command("backup", str(backup), stdout=io.StringIO())
        with tarfile.open(backup) as archive:
            rows = archive.extractfile("db.json").read().decode()
            data = archive.extractfile(f"media/{stored.file.name}").read()
        assert hashlib.sha256(data).hexdigest() == video["checksum"]
        assert '"model": "segmentation.referencevideo"' in rows and '"offset_s": 0.5' in rows

    def settings_media_parent(self):
        from django.conf import settings
        return Path(settings.MEDIA_ROOT).parent



def test_a_restored_backup_plays_the_same_video_at_the_same_offset(db, tmp_path, settings):
    """``manage.py restore`` into an empty installation gives back the video's row, its
    offset and its file, byte for byte."""
    from django.contrib.auth import get_user_model

    from segmentation import services
    from segmentation.services import videos
    from tests.segmentation.test_backup import fresh_installation, manage

    settings.MEDIA_ROOT = tmp_path / "media"
    alice = get_user_model().objects.create_user("alice", password="alice-password")
    project = services.do_create_project(alice, "Studio A")
    capture, _ = services.do_upload_capture(project, alice, SimpleUploadedFile("c.bvh", b"HIERARCHY"))
    path = make_video("vp9")
    video, _ = videos.do_upload_video(capture, alice, SimpleUploadedFile("side.webm", path.read_bytes()))
    videos.do_set_offset(video, alice, -0.75)
    backup = tmp_path / "cutroom.tar"
    call_command("backup", str(backup), stdout=io.StringIO())
    restored = fresh_installation(tmp_path / "restored")
    done = manage(restored, "restore", str(backup))
    assert done.returncode == 0, done.stderr
    check = manage(restored, "shell", "-v", "0", "-c", (
        "import hashlib; from segmentation.models import ReferenceVideo as V; v = V.objects.get(); "
        "print(v.name, v.offset_s, v.capture.name, hashlib.sha256(v.file.read()).hexdigest())"))
    assert check.returncode == 0, check.stderr
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    assert check.stdout.split() == ["side.webm", "-0.75", "c.bvh", digest]
