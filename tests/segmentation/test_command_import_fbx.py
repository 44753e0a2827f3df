"""``manage.py import_captures`` with FBX files: queued for the convert worker, the ones that
are not binary FBX reported by name at once."""

import io
import shutil
import tempfile
from pathlib import Path

from django.core.management import call_command

from segmentation.models import Capture
from tests.fbx.files import shared_fbx
from tests.segmentation.base import BaseTestCase


class ImportFbxTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.folder = Path(tempfile.mkdtemp(prefix="cutroom-import-fbx-"))
        self.addCleanup(shutil.rmtree, self.folder)

    def run_import(self, *paths):
        out, err = io.StringIO(), io.StringIO()
        call_command("import_captures", *map(str, paths), project="Studio A", stdout=out,
                     stderr=err)
        return out.getvalue()

    def test_it_queues_an_fbx_for_conversion(self):
        shutil.copy(shared_fbx("flair.fbx"), self.folder / "flair.fbx")
        out = self.run_import(self.folder)
        self.assertIn("Studio A: 1 imported, 0 duplicate, 0 failed", out)
        capture = Capture.objects.get()
        self.assertEqual((capture.name, capture.format, capture.status),
                         ("flair.fbx", "fbx", "queued"))
        self.assertEqual(capture.first_job(), "convert")

    def test_it_reports_an_ascii_fbx_by_name_without_importing_it(self):
        (self.folder / "old.fbx").write_text("; FBX 7.4.0 project file\nFBXHeaderExtension: {\n}\n")
        shutil.copy(shared_fbx("flair.fbx"), self.folder / "flair.fbx")
        out = self.run_import(self.folder)
        self.assertIn("Studio A: 1 imported, 0 duplicate, 1 failed", out)
        self.assertIn("old.fbx: ASCII FBX is not supported", out)
        self.assertEqual([c.name for c in Capture.objects.all()], ["flair.fbx"])
