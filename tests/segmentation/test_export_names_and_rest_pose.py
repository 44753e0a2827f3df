"""Bulk export names stay unique when two annotators cut the same range with the same
label, and a clip that starts at a cgspeed take's first frame leaves out its T-pose."""

import io
import json
import zipfile

from django.contrib.auth import get_user_model
from numpy.testing import assert_allclose

from segmentation import services
from segmentation.models import LibrarySegment
from tests.segmentation.test_library import submit_review
from tests.segmentation.test_library_cmu import CmuLibraryTestCase, data_file


class ExportRoughEdgesTest(CmuLibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture, self.take = self.real_capture(data_file("cmu", "bvh", "13_29.bvh"))
        self.login(self.rachel)

    def archive(self):
        body = b"".join(self.client.get(f"/api/segments/export.zip?capture={self.capture.pk}").streaming_content)
        return zipfile.ZipFile(io.BytesIO(body))

    def test_it_names_two_annotators_same_segment_apart(self):
        get_user_model().objects.create_user("dora", password="dora-password")
        services.do_set_member(self.project, "dora", "annotator")
        for user in (self.bob, get_user_model().objects.get(username="dora")):
            submit_review(self.capture, user, [469, 1000], [None, "Squat", None])
        archive = self.archive()
        names = archive.namelist()
        assert len(names) == len(set(names)) == 2 + 2
        files = sorted(row["file"] for row in json.loads(archive.read("manifest.json")))
        assert files == sorted(n for n in names if n.endswith(".bvh"))

    def test_a_clip_from_frame_0_of_a_cgspeed_take_leaves_out_the_t_pose(self):
        assert self.take.rest_pose_frame == 0
        submit_review(self.capture, self.bob, [469], ["JumpJack", None])
        segment = LibrarySegment.objects.get(label__name="JumpJack")
        response = self.client.get(f"/api/segments/{segment.pk}/export.bvh")
        path = self.media_root / "clip.bvh"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(response.content)
        import motionlib

        exported = motionlib.read(path)
        assert exported.n_frames == 469 - 1
        assert_allclose(exported.channels, self.take.channels[1:469], atol=1e-6)
