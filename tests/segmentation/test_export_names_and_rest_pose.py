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


class ExportFramesAgreeWithManifestTest(CmuLibraryTestCase):
    """Every format holds the frames the manifest names: a cgspeed clip from frame 0 leaves
    out the T-pose in BVH, FBX and glTF alike, and its manifest row says so."""

    def setUp(self):
        super().setUp()
        self.capture, self.take = self.real_capture(data_file("cmu", "bvh", "13_29.bvh"))
        self.login(self.rachel)
        submit_review(self.capture, self.bob, [469], ["JumpJack", None])

    def archive(self, fmt):
        url = f"/api/segments/export.zip?capture={self.capture.pk}&label=JumpJack&file_format={fmt}"
        body = b"".join(self.client.get(url).streaming_content)
        return zipfile.ZipFile(io.BytesIO(body))

    def frames_in(self, archive, name):
        import motionlib

        path = self.media_root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(archive.read(name))
        return motionlib.read(path).n_frames

    def test_it_lists_the_frames_each_bvh_clip_holds(self):
        archive = self.archive("bvh")
        [row] = json.loads(archive.read("manifest.json"))
        assert (row["start"], row["stop"], row["frames"]) == (1, 469, 468)
        assert self.frames_in(archive, row["file"]) == row["frames"]
        assert "BVH" in row["unit"]

    def test_it_lists_the_frames_and_unit_of_each_fbx_clip(self):
        archive = self.archive("fbx")
        [row] = json.loads(archive.read("manifest.json"))
        assert (row["start"], row["stop"], row["frames"]) == (1, 469, 468)
        assert self.frames_in(archive, row["file"]) == 468
        assert row["unit"] == ("metre; the capture's unit taken as CMU Acclaim unit (inch / "
                               "0.45) (chosen by the figure's height)")
        assert "frames,unit" in archive.read("manifest.csv").decode().splitlines()[0]
