"""``manage.py demo``: a project, its people and labels, generated and real takes, queued
for the worker exactly like uploads; a second run adds nothing."""

import io
import shutil
import tempfile
from pathlib import Path

from django.contrib.auth import authenticate, get_user_model
from django.core.management import call_command
from django.test import TestCase, override_settings

from segmentation import services
from segmentation.management.commands import demo
from segmentation.models import Capture, Label, Project
from segmentation.services.taxonomy import do_change_label
from tests.segmentation.base import SHARED_DATA, BaseTestCase


def run_demo(*args):
    out = io.StringIO()
    call_command("demo", *args, stdout=out)
    return out.getvalue()


class DemoTestCase(TestCase):
    """One demo run (generated takes only) shared by the tests of this class."""

    @classmethod
    def setUpClass(cls):
        # Class-level data is written before per-test settings apply: give it its own folder.
        media = tempfile.mkdtemp(prefix="cutroom-demo-")
        cls.addClassCleanup(shutil.rmtree, media)
        cls.enterClassContext(override_settings(MEDIA_ROOT=media))
        super().setUpClass()

    @classmethod
    def setUpTestData(cls):
        cls.output = run_demo("--no-shared-data")
        cls.project = Project.objects.get(name=demo.PROJECT)

    def test_it_prints_the_demo_logins(self):
        self.assertIn(f"Demo logins (password for all: {demo.PASSWORD})", self.output)
        for name in ("admin", "annotator", "reviewer"):
            self.assertRegex(self.output, rf"\n  {name} +{name}")

    def test_the_printed_logins_work(self):
        for name in ("admin", "annotator", "reviewer"):
            self.assertIsNotNone(authenticate(username=name, password=demo.PASSWORD), name)

    def test_each_demo_user_has_their_role_in_the_project(self):
        users = get_user_model().objects
        roles = {name: self.project.role_of(users.get(username=name)) for name in demo.USERS}
        self.assertEqual(roles, {"admin": "admin", "annotator": "annotator", "reviewer": "reviewer"})
        self.assertTrue(users.get(username="admin").is_superuser)
        self.assertFalse(users.get(username="annotator").is_staff)

    def test_the_taxonomy_has_colours_and_unique_hotkeys(self):
        labels = list(self.project.labels.all())
        names = [label.name for label in labels]
        for name in ("walk", "run", "jump", "squat", "punch", "kick", "jumping jack",
                     "arm circles", "idle"):
            self.assertIn(name, names)
        hotkeys = [label.hotkey for label in labels if label.hotkey]
        self.assertEqual(sorted(hotkeys), list("123456789"))
        self.assertTrue(all(label.color.startswith("#") and len(label.color) == 7
                            for label in labels))

    def test_it_adds_generated_takes_of_different_lengths_as_queued_uploads(self):
        captures = Capture.objects.filter(project=self.project).order_by("id")
        self.assertEqual([c.name for c in captures],
                         [f"synth-{seed}-{s:.0f}s.bvh" for seed, s in demo.SYNTH_TAKES])
        self.assertEqual({c.status for c in captures}, {"queued"})
        self.assertEqual({c.uploaded_by.username for c in captures}, {"annotator"})
        self.assertEqual(len({c.checksum for c in captures}), len(demo.SYNTH_TAKES))

    def test_a_second_run_adds_nothing_twice(self):
        before = (Capture.objects.count(), Label.objects.count(), Project.objects.count(),
                  get_user_model().objects.count())
        output = run_demo("--no-shared-data")
        after = (Capture.objects.count(), Label.objects.count(), Project.objects.count(),
                 get_user_model().objects.count())
        self.assertEqual(before, after)
        self.assertEqual(output.count("  present  synth-"), len(demo.SYNTH_TAKES))
        self.assertNotIn("  added ", output)

    def test_a_second_run_keeps_a_changed_password(self):
        user = get_user_model().objects.get(username="annotator")
        user.set_password("my-own-password")
        user.save()
        run_demo("--no-shared-data")
        self.assertIsNotNone(authenticate(username="annotator", password="my-own-password"))

    def test_a_second_run_keeps_a_label_the_admin_renamed(self):
        do_change_label(self.project.labels.get(name="turn"), name="spin")
        output = run_demo("--no-shared-data")
        names = list(self.project.labels.values_list("name", flat=True))
        self.assertIn("spin", names)
        self.assertNotIn("turn", names)
        self.assertIn("members and labels as its admins left them", output)

    def test_a_second_run_keeps_a_label_the_admin_removed(self):
        self.project.labels.filter(name="walk").delete()
        run_demo("--no-shared-data")
        self.assertFalse(self.project.labels.filter(name="walk").exists())

    def test_a_second_run_keeps_a_role_the_admin_changed(self):
        services.do_set_member(self.project, "reviewer", "annotator")
        run_demo("--no-shared-data")
        reviewer = get_user_model().objects.get(username="reviewer")
        self.assertEqual(self.project.role_of(reviewer), "annotator")

    def test_it_says_when_the_shared_data_folder_is_missing(self):
        output = run_demo("--shared-data", "/nonexistent/shared/data")
        self.assertIn("No CMU takes: /nonexistent/shared/data not found", output)
        self.assertEqual(Capture.objects.count(), len(demo.SYNTH_TAKES))


class DemoIngestTestCase(BaseTestCase):
    """The demo's takes go through the worker's jobs like any upload (run in-process here)."""

    def test_a_generated_take_is_ingested_and_gets_candidates(self):
        run_demo("--no-shared-data")
        capture = Capture.objects.get(name="synth-1-40s.bvh")
        capture = self.ingest(capture.pk)
        self.assertEqual((capture.status, capture.n_frames, capture.fps), ("ready", 4800, 120.0))
        self.assertGreater(len(capture.latest_finished_run().candidates), 0)

    def test_it_adds_the_cmu_takes_from_the_shared_data_folder(self):
        if not SHARED_DATA.is_dir():
            self.skipTest(f"real CMU data not found at {SHARED_DATA}")
        output = run_demo("--shared-data", str(SHARED_DATA))
        names = set(Capture.objects.values_list("name", flat=True))
        self.assertLessEqual({"13_29.bvh", "13_30.amc", "86_01.amc"}, names)
        self.assertIn("added    86_01.amc", output)
        amc = Capture.objects.get(name="13_30.amc")
        self.assertEqual(Path(amc.asf.name).name, "13.asf")
        amc = self.ingest(amc.pk)
        self.assertEqual((amc.status, amc.n_frames), ("ready", 2465), amc.error)
