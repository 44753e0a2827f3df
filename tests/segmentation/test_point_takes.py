"""Point takes in the service: C3D, Qualisys TSV and joint-position CSV uploads are ingested
with their points, links and gaps, detected, exported as C3D and CSV (and refused as BVH),
and their library segments get motion descriptors for similar search and label suggestions
(by body parts, or by the points themselves when no marker set is known)."""

import base64
import io
import json
import tempfile
import zipfile
from pathlib import Path

import numpy as np

import motionlib
from segmentation import importing, services, storage, suggestions, tasks
from segmentation.models import Label, LibrarySegment
from tests.motionlib.points_data import HDM05, points_file
from tests.segmentation.base import BaseTestCase, synthetic_bvh
from tests.segmentation.test_library import submit_review


class PointUploadTest(BaseTestCase):
    def upload_file(self, path, name=None):
        self.login(self.alice)
        response = self.upload(Path(path).read_bytes(), name=name or Path(path).name)
        assert response.status_code == 201, response.content
        return self.ingest(response.json()["id"])

    def test_it_ingests_a_c3d_with_its_markers_links_and_candidates(self):
        capture = self.upload_file(points_file(*HDM05))
        assert capture.status == "ready", capture.error
        assert (capture.format, capture.n_frames, capture.n_joints, capture.fps) == \
            ("c3d", 5920, 44, 120.0)
        skeleton = capture.skeleton
        assert (skeleton["kind"], skeleton["marker_set"], skeleton["unit"]) == \
            ("points", "plug-in gait", "mm")
        lelb = skeleton["joints"].index("Bastian:LELB")
        assert skeleton["joints"][skeleton["parents"][lelb]] == "Bastian:LSHO"
        assert len(capture.latest_finished_run().candidates) > 0

    def test_it_stores_the_gaps_of_a_kinect_csv_as_gaps(self):
        capture = self.upload_file(points_file("utkinect", "s01_e01.csv"))
        assert capture.status == "ready", capture.error
        stored = storage.load_npy(capture.positions)
        take = motionlib.read(points_file("utkinect", "s01_e01.csv"))
        np.testing.assert_array_equal(stored, take.positions.astype("<f4"))
        assert np.isnan(stored).any()
        assert capture.skeleton["first_number"] == 190

    def test_it_serves_the_points_of_a_frame_range(self):
        capture = self.upload_file(points_file("vmci", "subject1_run1.tsv"))
        assert capture.status == "ready", capture.error
        self.login(self.bob)
        answer = self.client.get(f"/api/captures/{capture.pk}/frames/?start=10&stop=20").json()
        block = np.frombuffer(base64.b64decode(answer["data"]), "<f4").reshape(10, 13, 3)
        take = motionlib.read(points_file("vmci", "subject1_run1.tsv"))
        np.testing.assert_array_equal(block, take.positions[10:20].astype("<f4"))
        assert len(capture.latest_finished_run().candidates) > 0

    def test_a_malformed_tsv_fails_naming_line_and_column_and_keeps_the_original(self):
        text = points_file("vmci", "subject1_run1.tsv").read_bytes().split(b"\n")
        cells = text[20].split(b"\t")
        cells[4] = b"12,5"
        text[20] = b"\t".join(cells)
        content = b"\n".join(text)
        capture = self.upload_file_bytes(content, "bad.tsv")
        assert capture.status == "failed"
        assert "bad.tsv:21: column 5 (Shoulder Z): '12,5' is not a number" in capture.error
        assert capture.original.read() == content

    def test_a_malformed_c3d_fails_naming_the_data_block(self):
        content = points_file(*HDM05).read_bytes()[:1_000_000]
        capture = self.upload_file_bytes(content, "short.c3d")
        assert capture.status == "failed"
        assert "short.c3d: data section (from block 10): the file ends in frame" in capture.error

    def upload_file_bytes(self, content, name):
        self.login(self.alice)
        response = self.upload(content, name=name)
        assert response.status_code == 201, response.content
        return self.ingest(response.json()["id"])

    def test_it_refuses_an_upload_of_another_extension_naming_the_point_formats(self):
        self.login(self.alice)
        response = self.upload(b"x", name="take.trc")
        assert response.status_code == 400
        assert ".c3d markers, a Qualisys .tsv export or a joint-position .csv" in \
            response.json()["detail"]

    def test_import_captures_reads_a_point_file_in_full_first(self):
        folder = Path(self.enterContext(tempfile.TemporaryDirectory()))
        (folder / "broken.csv").write_text("frame,a_x,a_y,a_z\n1,1,2,3\n2,1,2\n")
        outcome = importing.import_file(self.project, self.bob, folder / "broken.csv")
        assert outcome.status == "failed"
        assert "broken.csv:3: expected 4 cells, found 3" in outcome.reason


class PointLibraryTest(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.login(self.alice)
        content = points_file(*HDM05).read_bytes()
        response = self.upload(content, name="hdm05.c3d")
        self.capture = self.ingest(response.json()["id"])
        submit_review(self.capture, self.bob, [1200, 2400], ["walk", "punch", None])
        self.segment = LibrarySegment.objects.get(capture=self.capture, start=0)
        self.login(self.bob)

    def test_a_segment_downloads_as_a_trimmed_c3d_with_the_same_markers_rate_and_frames(self):
        response = self.client.get(f"/api/segments/{self.segment.pk}/export.c3d")
        assert response.status_code == 200
        assert response["Content-Disposition"].endswith('_walk_0-1200.c3d"')
        path = Path(self.enterContext(tempfile.TemporaryDirectory())) / "clip.c3d"
        path.write_bytes(response.content)
        clip = motionlib.read(path)
        take = motionlib.read(points_file(*HDM05))
        assert (clip.n_frames, clip.fps, clip.point_names) == (1200, 120.0, take.point_names)
        np.testing.assert_array_equal(clip.channels, take.channels[:1200])

    def test_a_segment_downloads_as_csv(self):
        second = LibrarySegment.objects.get(capture=self.capture, start=1200)
        response = self.client.get(f"/api/segments/{second.pk}/export.csv")
        assert response.status_code == 200
        path = Path(self.enterContext(tempfile.TemporaryDirectory())) / "clip.csv"
        path.write_bytes(response.content)
        clip = motionlib.read(path)
        take = motionlib.read(points_file(*HDM05))
        assert (clip.first_number, clip.n_frames, clip.unit, clip.up) == (1201, 1200, "mm", "z")
        np.testing.assert_array_equal(clip.channels, take.channels[1200:2400])

    def test_a_point_segment_is_not_exported_as_bvh(self):
        for url in (f"/api/segments/{self.segment.pk}/export.bvh",
                    f"/api/segments/{self.segment.pk}/export.glb"):
            response = self.client.get(url)
            assert response.status_code == 400, url
            assert "points (markers or tracked joints)" in response.json()["detail"]

    def test_the_zip_of_point_segments_holds_c3d_clips(self):
        response = self.client.get("/api/segments/export.zip?file_format=c3d")
        assert response.status_code == 200
        archive = zipfile.ZipFile(io.BytesIO(b"".join(response.streaming_content)))
        assert sorted(n for n in archive.namelist() if n.endswith(".c3d")) == [
            "hdm05_punch_1200-2400.c3d", "hdm05_walk_0-1200.c3d"]

    def test_the_zip_counts_and_holds_only_the_clips_its_format_writes(self):
        """Regression: a library of point and rotation takes exported as BVH announced every
        matching segment (the progress said 4 clips) and wrote 2."""
        self.login(self.alice)
        bvh = self.ingest(self.upload(synthetic_bvh(seed=3, duration=20.0), name="walks.bvh").json()["id"])
        submit_review(bvh, self.bob, [1200], ["walk", "punch"])
        self.login(self.bob)
        for fmt, clips in (("bvh", ["walks_punch_1200-2400.bvh", "walks_walk_0-1200.bvh"]),
                           ("c3d", ["hdm05_punch_1200-2400.c3d", "hdm05_walk_0-1200.c3d"])):
            response = self.client.get(f"/api/segments/export.zip?file_format={fmt}")
            assert response["X-Clip-Count"] == "2"
            archive = zipfile.ZipFile(io.BytesIO(b"".join(response.streaming_content)))
            assert sorted(n for n in archive.namelist() if n.endswith(f".{fmt}")) == clips
            assert len(json.loads(archive.read("manifest.json"))) == 2
            left_out = archive.read("errors.txt").decode()
            assert left_out.startswith("2 segments are not in this archive: "), left_out

    def test_point_segments_have_motion_descriptors_and_similar_segments(self):
        assert all(s.descriptor for s in LibrarySegment.objects.filter(capture=self.capture))
        response = self.client.get(f"/api/segments/{self.segment.pk}/similar/")
        assert response.status_code == 200, response.content
        assert [r["id"] for r in response.json()["results"]] != []



def vmci_truth(take, run):
    """[(start, stop, label)] of the top-level labelled segments of a vMCI run, take frames."""
    rows = json.loads(points_file("vmci", f"{run}_manually_segmented.json").read_text())
    return sorted((r["start index"] - take.first_number, r["end index"] - take.first_number,
                   r["label"]) for r in rows if not r["label"].endswith("_part"))


def cut_at(truth, n_frames):
    """Cuts at every labelled segment's ends, and each segment's label (None between)."""
    cuts = sorted({f for start, stop, _ in truth for f in (start, stop) if 0 < f < n_frames})
    bounds = [0, *cuts, n_frames]
    labels = {(start, stop): label for start, stop, label in truth}
    return cuts, [labels.get(span) for span in zip(bounds[:-1], bounds[1:], strict=True)]


class BarePointSimilarTest(BaseTestCase):
    """Two vMCI runs (13 arm, back and box markers: no known marker set) labelled by bob,
    a third cut but not labelled, and a skeleton take labelled with the same names."""

    def setUp(self):
        super().setUp()
        self.login(self.alice)
        self.truth = {}
        for run in ("subject1_run1", "subject1_run2", "subject1_run3"):
            path = points_file("vmci", f"{run}.tsv")
            capture = self.ingest(self.upload(path.read_bytes(), name=path.name).json()["id"])
            assert capture.status == "ready", capture.error
            self.truth[run] = (capture, vmci_truth(motionlib.read(path), run))
        for label in sorted({r[2] for _, truth in self.truth.values() for r in truth} | {"idle"}):
            if not Label.objects.filter(project=self.project, name=label).exists():
                services.do_add_label(self.project, label)
        for run in ("subject1_run1", "subject1_run2"):
            capture, truth = self.truth[run]
            submit_review(capture, self.bob, *cut_at(truth, capture.n_frames))
        self.skeleton = self.ingest(self.upload(synthetic_bvh(seed=4), name="walk.bvh").json()["id"])
        submit_review(self.skeleton, self.bob, [100, 200],
                      ["approach_forward", "move_obj_table", "idle"])

    def test_bare_point_segments_have_descriptors(self):
        capture, _ = self.truth["subject1_run1"]
        assert all(s.descriptor for s in LibrarySegment.objects.filter(capture=capture))

    def test_similar_finds_the_same_action_and_no_skeleton_clip(self):
        capture, truth = self.truth["subject1_run2"]
        self.login(self.bob)
        found = 0
        for start, stop, label in truth:
            segment = LibrarySegment.objects.get(capture=capture, start=start, stop=stop)
            response = self.client.get(f"/api/segments/{segment.pk}/similar/")
            assert response.status_code == 200, response.content
            results = response.json()["results"]
            assert self.skeleton.pk not in {r["capture"]["id"] for r in results}
            found += results[0]["label"] == label
        # Six actions, one other run labelled: chance is one in six.
        assert found >= 4, (found, len(truth))

    def test_a_skeleton_clip_finds_no_bare_point_clip(self):
        segment = LibrarySegment.objects.filter(capture=self.skeleton).first()
        self.login(self.bob)
        results = self.client.get(f"/api/segments/{segment.pk}/similar/").json()["results"]
        assert [r for r in results if r["id"] in set(LibrarySegment.objects.exclude(
            capture=self.skeleton).values_list("id", flat=True))] == []

    def test_label_suggestions_name_the_actions_of_an_unlabelled_run(self):
        capture, truth = self.truth["subject1_run3"]
        review = services.get_or_create_review(capture, self.bob)
        cuts, _ = cut_at(truth, capture.n_frames)
        for cut in list(review.cuts.all()):
            review = services.do_change_cut(review, self.bob, cut, review.version, fate="deleted")
        for frame in cuts:
            review = services.do_insert_cut(review, self.bob, frame, review.version)
        tasks.suggest(capture.pk, self.bob.pk)
        body = suggestions.for_review(capture, self.bob)
        suggested = {(s["start"], s["stop"]): s["label"] for s in body["suggestions"]}
        right = sum(suggested.get((start, stop)) == label for start, stop, label in truth)
        assert right >= 0.8 * len(truth), (right, len(truth), suggested)
