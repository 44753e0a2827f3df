"""Segments refer to labels by identity: renaming or retiring a label keeps every review,
gold version, library row, suggestion, dashboard figure and export consistent (issue 33,
item 1), and a retired label is not put on new gold segments (issue 36, item 3)."""

import csv
import io
import zipfile

from segmentation.models import Adjudication, LibrarySegment
from tests.segmentation.base import synthetic_bvh
from tests.segmentation.test_library import LibraryTestCase, submit_review


class LabelIdentityTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture, self.bob_review, _ = self.two_reviews()
        self.url = f"/api/captures/{self.capture.pk}/adjudication/"
        self.login(self.rachel)
        saved = self.save([100, 250], ["walk", "punch", "walk"], 0)
        assert saved.status_code == 200, saved.content

    def save(self, cuts, labels, version):
        return self.client.put(self.url, {"cuts": cuts, "labels": labels, "version": version},
                               format="json")

    def change(self, label, **fields):
        self.login(self.alice)
        r = self.client.patch(f"/api/projects/{self.project.pk}/labels/{label.pk}/", fields,
                              format="json")
        assert r.status_code == 200, r.content
        self.login(self.rachel)

    def test_gold_shows_a_renamed_label_under_its_new_name(self):
        self.change(self.walk, name="stroll")
        gold = self.client.get(self.url).json()["gold"]
        assert gold["labels"] == ["stroll", "punch", "stroll"]
        assert [s["label"] for s in gold["segments"]] == ["stroll", "punch", "stroll"]

    def test_gold_saved_as_returned_after_a_rename_is_accepted(self):
        self.change(self.walk, name="stroll")
        gold = self.client.get(self.url).json()["gold"]
        r = self.save(gold["cuts"], gold["labels"], gold["version"])
        assert r.status_code == 200, r.content
        assert Adjudication.objects.get().labels == [self.walk.pk, self.punch.pk, self.walk.pk]

    def test_the_library_filter_finds_the_new_name_and_not_the_old(self):
        self.change(self.walk, name="stroll")
        stroll = self.client.get("/api/segments/?label=stroll").json()
        assert stroll["count"] == 2
        assert {(r["start"], r["label"], r["gold"]) for r in stroll["results"]} == {
            (0, "stroll", True), (250, "stroll", True)}
        assert self.client.get("/api/segments/?label=walk&gold=false").json()["count"] == 0
        assert self.client.get("/api/segments/?label=stroll&gold=false").json()["count"] == 3

    def test_the_export_manifest_names_the_renamed_label(self):
        self.login(self.bob)
        capture = self.ingest(self.upload(synthetic_bvh(), name="synth.bvh").json()["id"])
        submit_review(capture, self.bob, [609], ["walk", "punch"])
        self.change(self.walk, name="stroll")
        r = self.client.get(f"/api/segments/export.zip?capture={capture.pk}")
        archive = zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content)))
        rows = list(csv.DictReader(io.StringIO(archive.read("manifest.csv").decode())))
        assert [(row["label"], row["file"]) for row in rows] == [
            ("stroll", "synth_stroll_0-609.bvh"), ("punch", "synth_punch_609-4468.bvh")]
        assert "errors.txt" not in archive.namelist()

    def test_the_dashboard_names_the_renamed_label(self):
        self.change(self.walk, name="stroll")
        body = self.client.get(f"/api/projects/{self.project.pk}/dashboard/").json()
        assert {entry["label"] for entry in body["labels"]} == {"stroll", "punch"}

    def test_a_rename_keeps_every_library_row(self):
        before = set(LibrarySegment.objects.values_list("id", "label_id"))
        self.change(self.walk, name="stroll")
        self.change(self.punch, name="jab")
        assert set(LibrarySegment.objects.values_list("id", "label_id")) == before


class RetiredLabelGoldTest(LabelIdentityTest):
    def test_adjudication_says_which_labels_are_retired(self):
        self.change(self.walk, retired=True)
        labels = {x["name"]: x["retired"] for x in self.client.get(self.url).json()["labels"]}
        assert labels == {"walk": True, "punch": False}

    def test_gold_saved_unchanged_keeps_a_label_retired_since(self):
        self.change(self.walk, retired=True)
        gold = self.client.get(self.url).json()["gold"]
        r = self.save(gold["cuts"], gold["labels"], gold["version"])
        assert r.status_code == 200, r.content
        assert r.json()["gold"]["labels"] == ["walk", "punch", "walk"]

    def test_gold_refuses_a_retired_label_on_a_new_segment(self):
        self.change(self.walk, retired=True)
        r = self.save([100, 250], ["walk", "walk", "walk"], 1)
        assert r.status_code == 400
        assert r.json()["detail"].startswith("labels: segment 1 has label 'walk', which is retired")
        assert Adjudication.objects.get().version == 1

    def test_gold_refuses_a_retired_label_on_a_moved_segment(self):
        self.change(self.walk, retired=True)
        r = self.save([100, 260], ["walk", "punch", "walk"], 1)
        assert r.status_code == 400
        assert "segment 2 has label 'walk', which is retired" in r.json()["detail"]

    def test_a_first_gold_version_may_adopt_a_reviews_label_retired_since(self):
        Adjudication.objects.all().delete()
        self.change(self.walk, retired=True)
        # bob's review labelled [0, 100) and [200, 300) walk before it was retired.
        r = self.save([100, 200, 300], ["walk", "punch", "walk", "punch"], 0)
        assert r.status_code == 200, r.content
