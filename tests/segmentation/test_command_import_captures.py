"""``manage.py import_captures``: folders of real files become captures, bad files are
reported by name and do not stop the run."""

import io
import shutil
import tempfile
from pathlib import Path

from django.core.management import CommandError, call_command

from segmentation.models import Capture
from tests.segmentation.base import SHARED_DATA, BaseTestCase, synthetic_bvh

CMU = SHARED_DATA / "cmu"


class ImportCapturesTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.folder = Path(tempfile.mkdtemp(prefix="cutroom-import-"))
        self.addCleanup(shutil.rmtree, self.folder)

    def write(self, relative, content):
        path = self.folder / relative
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(content)
        return path

    def run_import(self, *paths, **options):
        out, err = io.StringIO(), io.StringIO()
        options.setdefault("project", "Studio A")
        call_command("import_captures", *map(str, paths), stdout=out, stderr=err, **options)
        return out.getvalue(), err.getvalue()

    def need_cmu(self):
        if not CMU.is_dir():
            self.skipTest(f"real CMU data not found at {SHARED_DATA}")

    def test_it_imports_every_capture_in_a_folder_recursively(self):
        self.write("day1/a.bvh", synthetic_bvh(seed=1, duration=12.0))
        self.write("day1/more/b.BVH", synthetic_bvh(seed=2, duration=12.0))
        self.write("day1/notes.txt", b"not a capture")
        out, err = self.run_import(self.folder, user="bob")
        self.assertIn("Studio A: 2 imported, 0 duplicate, 0 failed", out)
        captures = Capture.objects.order_by("name")
        self.assertEqual([c.name for c in captures], ["a.bvh", "b.BVH"])
        self.assertEqual({(c.status, c.uploaded_by) for c in captures}, {("queued", self.bob)})
        self.assertIn("[###############...............] 1/2", err)
        self.assertIn("2/2", err)

    def test_it_stores_the_original_unchanged(self):
        content = synthetic_bvh(seed=3, duration=10.0)
        self.run_import(self.write("take.bvh", content))
        with Capture.objects.get().original.open("rb") as handle:
            self.assertEqual(handle.read(), content)

    def test_it_counts_a_file_already_in_the_project_as_a_duplicate(self):
        path = self.write("take.bvh", synthetic_bvh(seed=4, duration=10.0))
        self.run_import(path)
        self.write("copy/renamed.bvh", path.read_bytes())
        out, _ = self.run_import(self.folder)
        self.assertIn("0 imported, 2 duplicate, 0 failed", out)
        self.assertIn("(already capture", out)
        self.assertEqual(Capture.objects.count(), 1)

    def test_it_imports_a_file_named_twice_once(self):
        path = self.write("take.bvh", synthetic_bvh(seed=5, duration=10.0))
        out, _ = self.run_import(path, path, self.folder)
        self.assertIn("1 imported, 0 duplicate, 0 failed", out)

    def test_it_reports_bad_files_by_name_and_line_and_goes_on(self):
        good = synthetic_bvh(seed=6, duration=10.0)
        lines = good.decode().splitlines()
        motion = lines.index("MOTION")
        bad_header = lines[:motion + 1] + ["Frames: many"] + lines[motion + 2:]
        self.write("a_empty.bvh", b"")
        self.write("b_bad_header.bvh", "\n".join(bad_header).encode())
        self.write("c_good.bvh", good)
        out, _ = self.run_import(self.folder)
        self.assertIn("1 imported, 0 duplicate, 2 failed", out)
        self.assertIn("a_empty.bvh:1: empty file", out)
        self.assertRegex(out, rf"b_bad_header\.bvh:{motion + 2}: frame count must be a whole "
                              "number, found 'many'")
        self.assertEqual([c.name for c in Capture.objects.all()], ["c_good.bvh"])

    def test_it_leaves_a_bad_frame_to_the_worker_which_names_its_line(self):
        lines = synthetic_bvh(seed=6, duration=10.0).decode().splitlines()
        tokens = lines[-3].split()
        lines[-3] = " ".join(tokens[:2] + ["nan-ish"] + tokens[3:])
        self.write("bad_value.bvh", "\n".join(lines).encode())
        out, _ = self.run_import(self.folder)
        self.assertIn("1 imported", out)
        capture = self.ingest(Capture.objects.get().pk)
        self.assertEqual(capture.status, "failed")
        self.assertRegex(capture.error, rf"bad_value\.bvh:{len(lines) - 2}: .*'nan-ish'")

    def test_it_reads_every_frame_before_storing_with_full_check(self):
        lines = synthetic_bvh(seed=6, duration=10.0).decode().splitlines()
        tokens = lines[-3].split()
        lines[-3] = " ".join(tokens[:2] + ["nan-ish"] + tokens[3:])
        self.write("bad_value.bvh", "\n".join(lines).encode())
        out, _ = self.run_import(self.folder / "bad_value.bvh", self.write(
            "good.bvh", synthetic_bvh(seed=7, duration=10.0)), full_check=True)
        self.assertIn("1 imported, 0 duplicate, 1 failed", out)
        self.assertRegex(out, rf"bad_value\.bvh:{len(lines) - 2}: .*'nan-ish'")

    def test_it_reports_a_path_that_does_not_exist(self):
        good = self.write("good.bvh", synthetic_bvh(seed=7, duration=10.0))
        out, _ = self.run_import(self.folder / "missing.bvh", good)
        self.assertIn(f"{self.folder / 'missing.bvh'}: no such file or folder", out)
        self.assertIn("1 imported, 0 duplicate, 1 failed", out)

    def test_it_reports_a_named_file_that_is_not_a_capture(self):
        good = self.write("good.bvh", synthetic_bvh(seed=7, duration=10.0))
        notes = self.write("notes.txt", b"a,b\n")
        out, _ = self.run_import(notes, good)
        self.assertIn("extension '.txt' is not a capture", out)

    def test_it_fails_when_nothing_could_be_imported(self):
        self.write("empty.bvh", b"")
        with self.assertRaisesMessage(CommandError, "nothing was imported"):
            self.run_import(self.folder)

    def test_it_leaves_parsing_to_the_worker_with_no_check(self):
        self.write("broken.bvh", b"HIERARCHY\nROOT Hips\n{\n")
        out, _ = self.run_import(self.folder, no_check=True)
        self.assertIn("1 imported", out)
        capture = self.ingest(Capture.objects.get().pk)
        self.assertEqual(capture.status, "failed")
        self.assertIn("broken.bvh", capture.error)

    def test_imported_captures_are_ingested_and_detected_like_uploads(self):
        self.run_import(self.write("take.bvh", synthetic_bvh(seed=8, duration=30.0)))
        capture = self.ingest(Capture.objects.get().pk)
        self.assertEqual(capture.status, "ready", capture.error)
        self.assertEqual((capture.fps, capture.n_frames), (120.0, 3600))
        self.assertGreater(len(capture.latest_finished_run().candidates), 0)

    def test_it_refuses_an_unknown_project_and_lists_the_known_ones(self):
        with self.assertRaisesMessage(CommandError, "--project 'Nope': no such project"):
            self.run_import(self.folder, project="Nope")
        with self.assertRaisesMessage(CommandError, "'Studio A'"):
            self.run_import(self.folder, project="Nope")

    def test_it_accepts_a_project_id(self):
        self.write("take.bvh", synthetic_bvh(seed=9, duration=10.0))
        self.run_import(self.folder, project=str(self.project.pk))
        self.assertEqual(Capture.objects.get().project, self.project)

    def test_it_refuses_a_user_who_is_not_a_member(self):
        with self.assertRaisesMessage(CommandError, "--user 'charlie' is not a member"):
            self.run_import(self.folder, user="charlie")

    def test_it_refuses_an_unknown_user(self):
        with self.assertRaisesMessage(CommandError, "--user 'nobody': no such user"):
            self.run_import(self.folder, user="nobody")

    def test_it_finds_the_asf_of_a_cmu_amc_in_the_sibling_asf_folder(self):
        self.need_cmu()
        out, _ = self.run_import(CMU / "amc" / "13_30.amc")
        self.assertIn("1 imported", out)
        capture = Capture.objects.get()
        self.assertEqual((capture.format, capture.asf.name.rsplit("/", 1)[-1]), ("amc", "13.asf"))
        with capture.asf.open("rb") as handle:
            self.assertEqual(handle.read(), (CMU / "asf" / "13.asf").read_bytes())

    def test_it_imports_a_real_bvh_and_the_worker_reads_it(self):
        self.need_cmu()
        self.run_import(CMU / "bvh" / "13_29.bvh")
        capture = self.ingest(Capture.objects.get().pk)
        self.assertEqual((capture.status, capture.n_frames), ("ready", 4593))

    def test_it_uses_the_asf_given_with_the_asf_option(self):
        self.need_cmu()
        amc = self.write("takes/13_30.amc", (CMU / "amc" / "13_30.amc").read_bytes())
        out, _ = self.run_import(amc, asf=str(CMU / "asf" / "13.asf"))
        self.assertIn("1 imported", out)
        capture = self.ingest(Capture.objects.get().pk)
        self.assertEqual((capture.status, capture.n_frames), ("ready", 2465))

    def test_it_refuses_an_amc_without_an_asf_and_says_where_it_looked(self):
        self.need_cmu()
        self.write("takes/13_30.amc", (CMU / "amc" / "13_30.amc").read_bytes())
        self.write("good.bvh", synthetic_bvh(seed=10, duration=10.0))
        out, _ = self.run_import(self.folder)
        self.assertIn("13_30.amc: no ASF skeleton found (looked for", out)
        self.assertIn(str(self.folder / "takes" / "13.asf"), out)
        self.assertIn("pass --asf PATH", out)
        self.assertIn("1 imported, 0 duplicate, 1 failed", out)
