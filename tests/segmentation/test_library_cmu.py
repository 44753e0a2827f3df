"""The library on real CMU captures: trimmed BVH export (one segment and a streamed zip)
reads back to the source frames, similar clips of a squat are squats, and a new review's
unlabelled segments get the right suggested label."""

import csv
import io
import json
import zipfile
from functools import cache

import numpy as np
import pytest
from django.core.files.base import ContentFile
from numpy.testing import assert_allclose

import motionlib
from segmentation import services, tasks
from segmentation.files import storage
from segmentation.models import Capture, DetectionRun, LibrarySegment
from segmentation.services import gold
from tests.segmentation.base import SHARED_DATA
from tests.segmentation.test_library import LibraryTestCase, submit_review

MOCAP6 = ["JumpJack", "Jog", "Squat", "KneeRaise", "ArmCircle", "Twist", "ToeTouchOneHand"]


def data_file(*parts):
    path = SHARED_DATA.joinpath(*parts)
    if not path.is_file():
        pytest.skip(f"real CMU data {path} is not available (needs ../shared/data)")
    return path


@cache
def read(path, asf=None):
    return motionlib.read(path, asf=asf) if asf else motionlib.read(path)


def mocap6_actions(seq):
    """[(first frame, last frame + 1, action)] of a mocap6 take, in AMC frame numbers
    (the cgspeed BVH's motion line k is AMC frame k, so they are BVH frames too)."""
    rows = data_file("labels", "mocap6", "segments", f"{seq}.csv").read_text().splitlines()[1:]
    return [(int(r.split(",")[2]), int(r.split(",")[3]) + 1, r.split(",")[5]) for r in rows]


def clip_cuts(actions, n_frames, clip):
    """Cuts at every action boundary and every ``clip`` frames inside an action, with the
    label of each resulting segment (the part before the first action is unlabelled)."""
    cuts, labels = [], [None]
    for start, stop, action in actions:
        for frame in range(start, min(stop, n_frames), clip):
            if 0 < frame < n_frames and (stop - frame) >= clip // 2:
                cuts.append(frame)
                labels.append(action)
    return cuts, labels


class CmuLibraryTestCase(LibraryTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        for name in MOCAP6:
            services.do_add_label(cls.project, name)

    def real_capture(self, path, asf=None):
        """A ready capture of a real take, built from its parsed file (detection is not
        what these tests are about)."""
        take = read(path, asf)
        capture = Capture(
            project=self.project, uploaded_by=self.alice, name=path.name, format=take.format,
            checksum=path.name, status="ready", fps=take.fps, n_frames=take.n_frames,
            n_joints=len(take.skeleton.names),
            skeleton={"joints": list(take.skeleton.names),
                      "parents": [int(p) for p in take.skeleton.parents], "height": 1.0, "up": "y"},
        )
        capture.original.save(path.name, ContentFile(path.read_bytes()), save=False)
        if asf is not None:
            capture.asf.save(asf.name, ContentFile(asf.read_bytes()), save=False)
        positions = np.asarray(motionlib.forward_kinematics(take), dtype="<f4")
        storage.save_npy(capture.positions, "positions.npy", positions)
        capture.save()
        DetectionRun.objects.create(capture=capture, method="bone_angle", status="ready",
                                    candidates=[])
        return capture, take


class ExportTest(CmuLibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture, self.take = self.real_capture(data_file("cmu", "bvh", "13_29.bvh"))
        actions = mocap6_actions("13_29")
        submit_review(self.capture, self.bob, [a for a, _, _ in actions],
                      [None] + [name for _, _, name in actions])
        self.login(self.rachel)

    def test_it_exports_a_segment_as_trimmed_bvh_with_the_original_hierarchy(self):
        squat = LibrarySegment.objects.get(label__name="Squat")
        response = self.client.get(f"/api/segments/{squat.pk}/export.bvh")
        assert response.status_code == 200
        assert response["Content-Disposition"] == 'attachment; filename="13_29_Squat_3805-4593.bvh"'
        exported = self.read_back(response.content)
        assert exported.skeleton.names == self.take.skeleton.names
        assert exported.frame_time == pytest.approx(self.take.frame_time)
        assert exported.n_frames == 4593 - 3805
        assert_allclose(exported.channels, self.take.channels[3805:4593], atol=1e-6)

    def read_back(self, content, name="segment.bvh"):
        path = self.media_root / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)
        return motionlib.read(path)

    def test_it_streams_a_zip_of_the_query_with_a_manifest(self):
        response = self.client.get("/api/segments/export.zip?label=Squat")
        assert response.status_code == 200 and response.streaming
        archive = zipfile.ZipFile(io.BytesIO(b"".join(response.streaming_content)))
        assert sorted(archive.namelist()) == ["13_29_Squat_3805-4593.bvh", "manifest.csv",
                                              "manifest.json"]
        (entry,) = json.loads(archive.read("manifest.json"))
        assert entry | {"segment": None} == {
            "file": "13_29_Squat_3805-4593.bvh", "format": "bvh", "segment": None, "capture": "13_29.bvh",
            "capture_id": self.capture.pk, "start": 3805, "stop": 4593, "frames": 788,
            "unit": "the capture's own (BVH numbers as in the original)", "label": "Squat",
            "gold": False, "annotator": "bob", "agreement": None, "attributes": {}}
        rows = list(csv.DictReader(io.StringIO(archive.read("manifest.csv").decode())))
        assert rows[0]["label"] == "Squat" and rows[0]["annotator"] == "bob"
        exported = self.read_back(archive.read("13_29_Squat_3805-4593.bvh"))
        assert_allclose(exported.channels, self.take.channels[3805:4593], atol=1e-6)

    def test_it_puts_every_matching_segment_in_the_zip(self):
        response = self.client.get(f"/api/segments/export.zip?capture={self.capture.pk}")
        chunks = list(response.streaming_content)
        # Streamed: an empty chunk that sends the headers (the clip count), a chunk per
        # segment as it is written, then the manifests.
        assert chunks[0] == b"" and len(chunks) == 1 + 6 + 1 and all(chunks[1:7])
        names = zipfile.ZipFile(io.BytesIO(b"".join(chunks))).namelist()
        assert len(names) == 6 + 2
        assert "13_29_JumpJack_1-469.bvh" in names

    def test_it_hides_exports_of_segments_the_caller_may_not_see(self):
        squat = LibrarySegment.objects.get(label__name="Squat")
        for user in (self.dana, self.charlie):
            self.login(user)
            assert self.client.get(f"/api/segments/{squat.pk}/export.bvh").status_code == 404
            body = self.client.get("/api/segments/export.zip").streaming_content
            assert zipfile.ZipFile(io.BytesIO(b"".join(body))).namelist() == [
                "manifest.json", "manifest.csv"]


class AmcExportTest(CmuLibraryTestCase):
    def test_it_exports_an_amc_segment_as_bvh_with_the_same_poses(self):
        amc, asf = data_file("cmu", "amc", "13_30.amc"), data_file("cmu", "asf", "13.asf")
        capture, take = self.real_capture(amc, asf)
        submit_review(capture, self.bob, [1417, 1933], [None, "Squat", "Jog"])
        self.login(self.bob)
        squat = LibrarySegment.objects.get(label__name="Squat")
        response = self.client.get(f"/api/segments/{squat.pk}/export.bvh")
        assert response["Content-Disposition"] == 'attachment; filename="13_30_Squat_1417-1933.bvh"'
        path = self.media_root / "squat.bvh"
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(response.content)
        exported = motionlib.read(path)
        assert exported.n_frames == 1933 - 1417
        source = motionlib.forward_kinematics(take)[1417:1933]
        assert_allclose(motionlib.forward_kinematics(exported), source, atol=1e-3)


@pytest.mark.slow
class SimilarAndSuggestionsTest(CmuLibraryTestCase):
    def setUp(self):
        super().setUp()
        self.library_capture, _ = self.real_capture(data_file("cmu", "bvh", "13_29.bvh"))
        cuts, labels = clip_cuts(mocap6_actions("13_29"), 4593, 120)
        submit_review(self.library_capture, self.bob, cuts, labels)
        self.library_cuts = (cuts, labels)

    def test_it_ranks_squats_nearest_to_a_squat(self):
        self.login(self.rachel)
        squats = LibrarySegment.objects.filter(label__name="Squat").order_by("start")
        query = squats[1]
        body = self.client.get(f"/api/segments/{query.pk}/similar/?k=3").json()
        assert body["segment"] == query.pk
        assert [r["label"] for r in body["results"]] == ["Squat"] * 3
        distances = [r["distance"] for r in body["results"]]
        assert distances == sorted(distances)
        assert query.pk not in [r["id"] for r in body["results"]]

    def test_it_ranks_twists_nearest_to_a_twist(self):
        self.login(self.rachel)
        twist = LibrarySegment.objects.filter(label__name="Twist").order_by("start")[1]
        body = self.client.get(f"/api/segments/{twist.pk}/similar/?k=3").json()
        assert [r["label"] for r in body["results"]] == ["Twist"] * 3

    def test_it_suggests_labels_for_a_new_takes_unlabelled_segments(self):
        capture, _ = self.real_capture(data_file("cmu", "amc", "13_30.amc"),
                                       data_file("cmu", "asf", "13.asf"))
        actions = mocap6_actions("13_30")
        cuts, labels = clip_cuts(actions, capture.n_frames, 120)
        self.login(self.dana)
        review = services.get_or_create_review(capture, self.dana)
        for frame in cuts:
            review = services.do_insert_cut(review, self.dana, frame, review.version)
        # dana may see gold and her own segments only: bob's 13_29 becomes gold.
        gold.do_save_gold(self.library_capture, self.rachel, *self.library_cuts, version=0)
        tasks.suggest(capture.pk, self.dana.pk)
        url = f"/api/captures/{capture.pk}/review/suggestions/"
        suggested = {s["start"]: s["label"] for s in self.client.get(url).json()["suggestions"]}
        segments = self.client.get(f"/api/captures/{capture.pk}/review/").json()["segments"]
        # 13_29 has no Jog: those clips cannot be named; the rest mostly can.
        known = [(suggested[s["start"]], truth) for s, truth in zip(segments, labels, strict=True)
                 if truth not in (None, "Jog")]
        hits = sum(label == truth for label, truth in known)
        assert hits / len(known) >= 0.8, known
        # A labelled segment needs no suggestion.
        review = services.do_label_segment(review, self.dana, 1, "JumpJack", review.version)
        suggested = {s["start"]: s["label"] for s in self.client.get(url).json()["suggestions"]}
        assert segments[1]["start"] not in suggested
