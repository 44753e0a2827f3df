"""Migration 0013: a project or run whose stored parameters hold the default detector's
options that lost out of sample (``tempo``, ``short_activity``, ``short_uniformity``)
still detects once they are dropped."""

import importlib

from django.apps import apps

from segmentation import tasks
from segmentation.models import DetectionRun, Project
from tests.segmentation.base import BaseTestCase, synthetic_bvh

migration = importlib.import_module("segmentation.migrations.0013_drop_losing_detector_options")

LOSING = {"tempo": True, "short_activity": 4.0, "short_uniformity": 0.3}


def migrate():
    migration.drop_losing_options(apps, None)


class DropLosingOptionsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        Project.objects.filter(pk=self.project.pk).update(
            default_method="default", default_params={"threshold": 0.2, **LOSING})
        self.project.refresh_from_db()

    def upload_and_ingest(self, seed):
        self.login(self.alice)
        response = self.upload(synthetic_bvh(seed=seed, duration=20.0), name=f"take_{seed}.bvh")
        return self.ingest(response.json()["id"])

    def test_a_project_holding_them_is_refused_before_the_migration(self):
        capture = self.upload_and_ingest(seed=11)
        run = capture.runs.get()
        self.assertEqual(run.status, "failed")
        self.assertIn("short_activity: unknown parameter for method 'default'", run.error)

    def test_it_drops_them_and_keeps_the_project_s_other_parameters(self):
        migrate()
        self.project.refresh_from_db()
        self.assertEqual(self.project.default_params, {"threshold": 0.2})

    def test_a_project_holding_them_detects_after_the_migration(self):
        migrate()
        capture = self.upload_and_ingest(seed=12)
        run = capture.runs.get()
        self.assertEqual(run.status, "ready", run.error)
        self.assertEqual(run.params["threshold"], 0.2)
        self.assertTrue(run.candidates)
        self.assertFalse(set(LOSING) & set(run.params))

    def test_it_leaves_a_project_of_another_method_alone(self):
        Project.objects.filter(pk=self.other_project.pk).update(
            default_method="bone_angle", default_params={"param": 0.3})
        migrate()
        self.other_project.refresh_from_db()
        self.assertEqual(self.other_project.default_params, {"param": 0.3})

    def test_a_failed_run_holding_them_detects_when_retried_after_the_migration(self):
        Project.objects.filter(pk=self.project.pk).update(default_params={})
        capture = self.upload_and_ingest(seed=13)
        run = capture.runs.get()
        self.assertEqual(run.status, "ready", run.error)
        DetectionRun.objects.filter(pk=run.pk).update(
            status="failed", error="the worker was lost 3 times", params={**run.params, **LOSING})
        migrate()
        self.assertTrue(DetectionRun.objects.requeue_failed(run.pk))
        tasks.detect(run.pk)
        run.refresh_from_db()
        self.assertEqual(run.status, "ready", run.error)
        self.assertFalse(set(LOSING) & set(run.params))

    def test_a_finished_run_keeps_the_parameters_it_ran_with(self):
        Project.objects.filter(pk=self.project.pk).update(default_params={})
        run = self.upload_and_ingest(seed=14).runs.get()
        DetectionRun.objects.filter(pk=run.pk).update(params={**run.params, **LOSING})
        migrate()
        run.refresh_from_db()
        self.assertEqual({k: run.params[k] for k in LOSING}, LOSING)
