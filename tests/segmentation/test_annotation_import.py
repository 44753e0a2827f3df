"""Importing existing annotations into a review or into gold, through the API (issue 49,
item 2): CSV, ELAN .eaf written by pympi-ling, Label Studio JSON; unknown labels mapped or
refused, never created; bad rows named; the import one step of the review's history; who
may import where."""

import json

import pympi
from django.core.files.uploadedfile import SimpleUploadedFile

from segmentation.models import Adjudication, Label, ReviewEvent
from tests.segmentation.base import BaseTestCase
from tests.segmentation.test_library import submit_review

# 400 frames at 120 fps: walk 0..100, a gap, Punch 150..250, jump 250..400.
CSV = ("take,start_frame,end_frame,label\n"
       "c.bvh,0,100,walk\n"
       "c.bvh,150,250,Punch\n"
       "c.bvh,250,400,jump\n"
       "other.bvh,0,10,walk\n")


def eaf_bytes(tmp_dir):
    """An ELAN file written by pympi: tier "moves" like CSV above, tier "notes" another."""
    eaf = pympi.Elan.Eaf()
    eaf.add_tier("moves")
    eaf.add_annotation("moves", 0, 833, "walk")        # frames 0..100
    eaf.add_annotation("moves", 1250, 2083, "punch")   # 150..250
    eaf.add_tier("notes")
    eaf.add_annotation("notes", 0, 3333, "walk")
    path = tmp_dir / "take.eaf"
    eaf.to_file(str(path))
    return path.read_bytes()


class ImportBase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200, 300), n_frames=400, name="c.bvh")
        self.base = f"/api/captures/{self.capture.pk}/annotations/"

    def send(self, step, content, name="labels.csv", **fields):
        data = {"file": SimpleUploadedFile(name, content.encode() if isinstance(content, str) else content),
                **{k: v if isinstance(v, str | int) else json.dumps(v) for k, v in fields.items()}}
        return self.client.post(self.base + f"{step}/", data, format="multipart")

    def review(self):
        return self.client.get(f"/api/captures/{self.capture.pk}/review/").json()


class ReviewImportTest(ImportBase):
    def test_inspect_lists_the_unknown_labels_and_writes_nothing(self):
        self.login(self.bob)
        r = self.send("inspect", CSV)
        assert r.status_code == 200, r.content
        body = r.json()
        assert body["format"] == "csv" and body["chosen"] and body["other_takes"] == 1
        # Rows of other takes are not this capture's.
        assert [(s["start"], s["stop"], s["label"]) for s in body["segments"]] == [
            (0, 100, "walk"), (150, 250, "Punch"), (250, 400, "jump")]
        assert body["labels"] == [
            {"name": "walk", "count": 1, "known": True, "suggestion": None},
            {"name": "Punch", "count": 1, "known": False, "suggestion": "punch"},
            {"name": "jump", "count": 1, "known": False, "suggestion": None}]
        assert self.review()["id"] is None  # no review started

    def test_it_refuses_unknown_labels_until_each_is_mapped_and_creates_none(self):
        self.login(self.bob)
        labels = Label.objects.count()
        r = self.send("import", CSV, version=1)
        assert r.status_code == 400
        assert r.json()["detail"].startswith("labels: 'Punch', 'jump' are not labels of this "
                                             "project; map each to one of (punch, walk)")
        r = self.send("import", CSV, version=1, mapping={"Punch": "punch", "jump": "kick"})
        assert r.status_code == 400
        assert "mapping: 'jump' -> 'kick': map to a label in use" in r.json()["detail"]
        assert Label.objects.count() == labels and self.review()["id"] is None

    def test_it_makes_the_review_the_files_segments_as_one_import_event(self):
        self.login(self.bob)
        r = self.send("import", CSV, version=1, mapping={"Punch": "punch", "jump": "walk"})
        assert r.status_code == 200, r.content
        review = r.json()["review"]
        assert [(s["start"], s["stop"], s["label"]) for s in review["segments"]] == [
            (0, 100, "walk"), (100, 150, None), (150, 250, "punch"), (250, 400, "walk")]
        fates = {(c["frame"], c["origin"]): c["fate"] for c in review["cuts"]}
        assert fates == {(100, "candidate"): "accepted", (200, "candidate"): "deleted",
                         (300, "candidate"): "deleted", (150, "inserted"): "accepted",
                         (250, "inserted"): "accepted"}
        events = ReviewEvent.objects.filter(review_id=review["id"]).order_by("id")
        assert [e.action for e in events] == ["create", "import"]
        assert events[1].user == self.bob
        assert events[1].after["file"] == "labels.csv" and events[1].after["segments"] == 3
        assert events[1].after["mapping"] == {"Punch": "punch", "jump": "walk"}

    def test_one_undo_takes_the_import_back_and_redo_makes_it_again(self):
        self.login(self.bob)
        before = self.client.post(f"/api/captures/{self.capture.pk}/review/").json()
        self.client.patch(f"/api/captures/{self.capture.pk}/review/segments/0/",
                          {"label": "punch", "version": before["version"]}, format="json")
        before = self.review()
        imported = self.send("import", CSV, version=before["version"],
                             mapping={"Punch": "punch", "jump": "walk"}).json()["review"]
        url = f"/api/captures/{self.capture.pk}/review/"
        undone = self.client.post(url + "undo/", {"version": imported["version"]}, format="json").json()
        assert undone["segments"] == before["segments"]
        assert ({c["frame"]: c["fate"] for c in undone["cuts"] if c["fate"] != "deleted"}
                == {c["frame"]: c["fate"] for c in before["cuts"] if c["fate"] != "deleted"})
        redone = self.client.post(url + "redo/", {"version": undone["version"]}, format="json").json()
        assert redone["segments"] == imported["segments"]

    def test_it_imports_the_chosen_tier_of_an_elan_file(self):
        self.login(self.bob)
        content = eaf_bytes(self.tmp())
        body = self.send("inspect", content, name="take.eaf").json()
        assert body["sources"] == ["moves", "notes"] and not body["chosen"]
        r = self.send("import", content, name="take.eaf", version=1)
        assert r.status_code == 400 and "holds 2 sources ('moves', 'notes'); choose one" in r.json()["detail"]
        r = self.send("import", content, name="take.eaf", source="moves", version=1)
        assert r.status_code == 200, r.content
        assert [(s["start"], s["stop"], s["label"]) for s in r.json()["review"]["segments"]] == [
            (0, 100, "walk"), (100, 150, None), (150, 250, "punch"), (250, 400, None)]

    def test_it_imports_a_label_studio_export(self):
        export = [{"id": 5, "data": {"ts": "/data/upload/1/9f8e7d6c-c.csv"}, "annotations": [
            {"id": 9, "result": [{"id": "r", "type": "timeserieslabels", "from_name": "label",
                                  "to_name": "ts", "value": {"start": 0.5, "end": 1.25,
                                                            "timeserieslabels": ["walk"]}}]}]}]
        self.login(self.bob)
        r = self.send("import", json.dumps(export), name="export.json", version=1)
        assert r.status_code == 200, r.content
        assert [(s["start"], s["stop"], s["label"]) for s in r.json()["review"]["segments"]] == [
            (0, 60, None), (60, 150, "walk"), (150, 400, None)]

    def test_bad_rows_are_named_by_line_never_a_500(self):
        self.login(self.bob)
        cases = [
            ("take,start,end,label\nc.bvh,10,5,walk\nc.bvh,0,500,walk\n", "labels.csv",
             "labels.csv: line 2: end (frame 5) is not after start (frame 10); line 3: frames "
             "0..500 are outside the take (0..400, end exclusive)"),
            ("take,start,end,label\nc.bvh,0,100,walk\nc.bvh,50,150,walk\n", "labels.csv",
             "labels.csv: line 3 (frames 50..150) overlaps line 2 (frames 0..100)"),
            ("take,start,end,label\nc.bvh,zero,100,walk\n", "labels.csv",
             "labels.csv: line 2: start: 'zero' is not a time in seconds, a frame number or a timecode"),
            ("take,start,end,label\nnope.bvh,0,100,walk\n", "labels.csv",
             "take: no annotation of labels.csv is for take 'c.bvh'; the file names 'nope.bvh'"),
            (b"\xff\xfe\x00", "labels.csv", "labels.csv: byte 0 is not UTF-8 text"),
            ("[1, 2]", "x.json", "x.json: a Label Studio export is a list of tasks"),
            ("hello", "x.docx", "x.docx: cannot tell the format from the extension '.docx'"),
            ("<ANNOTATION_DOCUMENT>", "x.eaf", "x.eaf: line 1, column 21: not well-formed XML"),
        ]
        for content, name, message in cases:
            r = self.send("import", content, name=name, version=1)
            assert r.status_code == 400, (name, r.content)
            assert message in r.json()["detail"], (message, r.json())
        assert self.review()["id"] is None

    def test_a_stale_version_is_refused_with_the_current_review(self):
        self.login(self.bob)
        self.client.post(f"/api/captures/{self.capture.pk}/review/")
        r = self.send("import", "start,end,label\n0,100,walk\n", version=7)
        assert r.status_code == 409 and r.json()["review"]["version"] == 1

    def test_a_submitted_review_takes_no_import(self):
        submit_review(self.capture, self.bob, [100], ["walk", "punch"])
        self.login(self.bob)
        r = self.send("import", "start,end,label\n0,100,walk\n", version=self.review()["version"])
        assert r.status_code == 400 and "was submitted" in r.json()["detail"]

    def test_an_outsider_gets_404(self):
        self.login(self.charlie)
        for step in ("inspect", "import"):
            r = self.send(step, CSV, version=1)
            assert r.status_code == 404, r.content

    def tmp(self):
        import tempfile
        from pathlib import Path
        folder = tempfile.TemporaryDirectory()
        self.addCleanup(folder.cleanup)
        return Path(folder.name)


class GoldImportTest(ImportBase):
    CSV = "start,end,label\n0,100,walk\n100,400,punch\n"

    def test_a_reviewer_imports_into_gold(self):
        submit_review(self.capture, self.bob, [100, 200], ["walk", "punch", "walk"])
        self.login(self.rachel)
        r = self.send("import", self.CSV, target="gold", version=0)
        assert r.status_code == 200, r.content
        assert r.json()["gold"] == {"cuts": [100], "labels": ["walk", "punch"], "version": 1}
        adjudication = self.client.get(f"/api/captures/{self.capture.pk}/adjudication/").json()
        assert adjudication["gold"]["cuts"] == [100]
        # Stale: the gold version is 1 now.
        assert self.send("import", self.CSV, target="gold", version=0).status_code == 409

    def test_annotators_are_refused_and_outsiders_get_404(self):
        submit_review(self.capture, self.bob, [100], ["walk", "punch"])
        self.login(self.bob)
        for step in ("inspect", "import"):
            r = self.send(step, self.CSV, target="gold", version=0)
            assert r.status_code == 403, r.content
            assert "reviewers and admins" in r.json()["detail"]
        self.login(self.charlie)
        for step in ("inspect", "import"):
            assert self.send(step, self.CSV, target="gold", version=0).status_code == 404
        assert not Adjudication.objects.filter(capture=self.capture).exists()


def test_the_services_read_the_format_package_whatever_was_imported_before():
    """``motionlib.io`` has ``from __future__ import annotations``: ``from motionlib.io
    import annotations`` gave that feature object, not the package, unless something had
    imported the package first. A fresh interpreter imports the services alone."""
    import subprocess
    import sys

    code = ("import os, django; os.environ.setdefault('DJANGO_SETTINGS_MODULE', 'cutroom.settings');"
            "django.setup(); from segmentation.services import annotations;"
            "from segmentation.files import annotation_exports as exports;"
            "print(annotations.fmt.Track.__name__, exports.fmt.write_eaf.__name__)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.split() == ["Track", "write_eaf"], result.stderr[-500:]
