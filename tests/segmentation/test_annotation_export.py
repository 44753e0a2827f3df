"""Exporting annotations per capture and from a library query (issue 49, item 3): the
files re-import to the same segments, pympi-ling reads the ELAN ones, and each role
exports only what it sees."""

import csv
import io
import json
import tempfile
import zipfile

import pympi
from django.core.files.uploadedfile import SimpleUploadedFile

from motionlib.io.annotations import read_annotations, select
from tests.segmentation.test_library import LibraryTestCase, submit_review


class CaptureExportTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200, 300), n_frames=400, name="c.bvh")
        self.url = f"/api/captures/{self.capture.pk}/annotations/"
        self.bob_review = submit_review(self.capture, self.bob, [100, 200], ["walk", None, "punch"])

    def export(self, form, source="mine"):
        return self.client.get(self.url + f"export.{form}?source={source}")

    def test_each_format_imports_back_to_the_same_segments(self):
        self.login(self.bob)
        wanted = [(0, 100, "walk"), (100, 200, None), (200, 400, "punch")]
        for form, name in (("csv", "c.csv"), ("eaf", "c.eaf"), ("labelstudio", "c.json")):
            r = self.export(form)
            assert r.status_code == 200, r.content
            assert r["Content-Disposition"] == f'attachment; filename="{name}"'
            # dana's review starts from nothing and imports bob's file.
            self.login(self.dana)
            upload = SimpleUploadedFile(name, r.content)
            start = self.client.post(f"/api/captures/{self.capture.pk}/review/").json()
            imported = self.client.post(self.url + "import/", {"file": upload, "version": start["version"]},
                                        format="multipart")
            assert imported.status_code == 200, imported.content
            got = [(s["start"], s["stop"], s["label"]) for s in imported.json()["review"]["segments"]]
            # Label Studio regions need a label: the gap comes back as a gap all the same.
            assert got == wanted, form
            self.login(self.bob)

    def test_pympi_reads_the_exported_elan_file(self):
        self.login(self.bob)
        content = self.export("eaf").content
        with tempfile.NamedTemporaryFile(suffix=".eaf") as handle:
            handle.write(content)
            handle.flush()
            eaf = pympi.Elan.Eaf(handle.name)
        assert list(eaf.get_tier_names()) == ["bob"]
        assert eaf.get_annotation_data_for_tier("bob") == [
            (0, 833, "walk"), (833, 1667, ""), (1667, 3333, "punch")]

    def test_reviewers_export_every_review_and_gold_annotators_only_theirs(self):
        submit_review(self.capture, self.dana, [150], ["punch", "walk"])
        self.login(self.rachel)
        self.client.put(f"/api/captures/{self.capture.pk}/adjudication/",
                        {"cuts": [100], "labels": ["walk", "punch"], "version": 0}, format="json")
        text = self.export("csv", "all").content.decode()
        assert {row.split(",")[1] for row in text.splitlines()[1:]} == {"bob", "dana", "gold"}
        self.login(self.bob)
        assert self.export("csv", "all").status_code == 403
        dana = self.capture.reviews.get(annotator=self.dana)
        assert self.export("csv", str(dana.pk)).status_code == 403
        assert self.export("csv", str(self.bob_review.pk)).status_code == 200
        gold = self.export("eaf", "gold")
        assert gold.status_code == 200 and b'TIER_ID="gold"' in gold.content
        self.login(self.charlie)
        assert self.export("csv").status_code == 404

    def test_the_csv_carries_each_segments_attribute_values_and_imports_back(self):
        """Issue 49, item 5: attributes travel in the CSV, one ``attribute:<name>`` column each
        (a yes/no as true/false; empty where a segment has none); the ELAN and Label Studio
        files keep only cuts and labels."""
        from segmentation.models import SegmentAttributeValue
        from segmentation.services import attributes

        quality = attributes.do_add_attribute(self.project, "quality", "choice", ["good", "unusable"])
        cleanup = attributes.do_add_attribute(self.project, "=needs cleanup", "boolean")
        cut_200 = self.bob_review.cuts.get(frame=200)
        SegmentAttributeValue.objects.create(review=self.bob_review, cut=None, attribute=quality, value="good")
        SegmentAttributeValue.objects.create(review=self.bob_review, cut=cut_200, attribute=quality,
                                             value="unusable")
        SegmentAttributeValue.objects.create(review=self.bob_review, cut=cut_200, attribute=cleanup,
                                             value="true")
        self.login(self.bob)
        text = self.export("csv").content.decode()
        rows = list(csv.DictReader(io.StringIO(text)))
        assert [(r["start_frame"], r["attribute:quality"], r["attribute:=needs cleanup"]) for r in rows] == [
            ("0", "good", ""), ("100", "", ""), ("200", "unusable", "true")]
        records = read_annotations(text.encode(), "c.csv", "csv", fps=120.0)
        assert [(r.start, r.stop, r.label) for r in records] == [
            (0, 100, "walk"), (100, 200, None), (200, 400, "punch")]

    def test_bad_export_requests_are_named(self):
        self.login(self.bob)
        assert self.export("docx").status_code == 404
        r = self.export("csv", "everyone")
        assert r.status_code == 400
        assert r.json()["detail"] == "source: must be mine, gold, all or a review id, got 'everyone'"
        self.login(self.alice)
        r = self.export("csv")
        assert r.status_code == 400 and "you have not started a review" in r.json()["detail"]


class LibraryExportTest(LibraryTestCase):
    def test_a_library_query_exports_its_segments_in_each_format(self):
        capture, _, _ = self.two_reviews()
        other = self.ready_capture(candidates=(50,), n_frames=200, name="d.bvh")
        submit_review(other, self.bob, [50], ["punch", "walk"])
        self.login(self.rachel)
        text = self.client.get("/api/segments/annotations.csv?label=walk").content.decode()
        rows = [line.split(",") for line in text.splitlines()[1:]]
        assert {r[2] for r in rows} == {"walk"} and {r[0] for r in rows} == {"c.bvh", "d.bvh"}
        records = read_annotations(text.encode(), "a.csv", "csv", fps=120.0)
        assert [(r.start, r.stop) for r in select(records, take="d.bvh", source="bob", name="a")] == [(50, 200)]

        archive = zipfile.ZipFile(io.BytesIO(self.client.get("/api/segments/annotations.eaf").content))
        assert sorted(archive.namelist()) == ["c.eaf", "d.eaf"]
        assert b'TIER_ID="dana"' in archive.read("c.eaf")
        tasks = json.loads(self.client.get(f"/api/segments/annotations.labelstudio?capture={capture.pk}").content)
        assert [t["data"]["take"] for t in tasks] == ["c.bvh"] and len(tasks[0]["annotations"]) == 2

    def test_an_annotator_exports_only_their_own_and_gold_segments(self):
        self.two_reviews()
        self.login(self.bob)
        text = self.client.get("/api/segments/annotations.csv").content.decode()
        assert {line.split(",")[1] for line in text.splitlines()[1:]} == {"bob"}
        assert self.client.get("/api/segments/annotations.xml").status_code == 404
        r = self.client.get("/api/segments/annotations.csv?min_duration=x")
        assert r.status_code == 400 and "min_duration" in r.json()["detail"]
