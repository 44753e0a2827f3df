"""Training a project's cut model: when it is asked for, one at a time per project, what
it learns from, and what a failure leaves behind. (Training itself with a real worker:
tests/segmentation/integration/test_adaptation_flow.py.)"""

from django.test import override_settings
from django.utils import timezone

from segmentation import tasks
from segmentation.models import ProjectCutModel
from segmentation.services import adaptation, gold, jobs
from tests.segmentation.base import BaseTestCase


def commit(callbacks):
    """Run what a transaction deferred to its commit (sends to the broker are left out:
    they are registered by these callbacks, after the list was captured)."""
    for callback in callbacks:
        callback()


class AdaptationTestCase(BaseTestCase):
    def submit_review(self, capture, user, keep=None):
        """``user`` opens ``capture`` for review, keeps the candidates in ``keep`` (all
        when None) and submits; returns the commit callbacks of the submit."""
        self.login(user)
        review = self.client.post(f"/api/captures/{capture.pk}/review/").json()
        version = review["version"]
        for cut in review["cuts"]:
            if keep is not None and cut["frame"] not in keep:
                version = self.client.patch(
                    f"/api/captures/{capture.pk}/review/cuts/{cut['id']}/",
                    {"fate": "deleted", "version": version}, format="json",
                ).json()["version"]
        with self.captureOnCommitCallbacks() as callbacks:
            r = self.client.post(f"/api/captures/{capture.pk}/review/submit/",
                                 {"version": version}, format="json")
        self.assertEqual(r.status_code, 200, r.content)
        return callbacks

    def trained(self, version, n_takes=2, project=None):
        return ProjectCutModel.objects.create(
            project=project or self.project, status="ready", version=version,
            model='{"format": 1}', n_takes=n_takes, n_cuts=3 * n_takes,
        )


class TrainingRequestTestCase(AdaptationTestCase):
    def test_it_asks_for_a_training_once_a_submit_commits(self):
        callbacks = self.submit_review(self.ready_capture(), self.bob)
        self.assertFalse(ProjectCutModel.objects.exists())
        commit(callbacks)
        job = ProjectCutModel.objects.get()
        self.assertEqual((job.project, job.status, job.version), (self.project, "queued", None))

    def test_it_asks_for_a_training_once_a_gold_version_is_saved(self):
        capture = self.ready_capture()
        commit(self.submit_review(capture, self.bob))
        ProjectCutModel.objects.all().delete()
        with self.captureOnCommitCallbacks() as callbacks:
            gold.do_save_gold(capture, self.rachel, [150], ["walk", "punch"], 0)
        self.assertFalse(ProjectCutModel.objects.exists())
        commit(callbacks)
        self.assertEqual(ProjectCutModel.objects.get().status, "queued")

    def test_requests_made_while_a_training_waits_join_it(self):
        with self.captureOnCommitCallbacks() as sends:
            first = adaptation.request_training(self.project.pk)
            second = adaptation.request_training(self.project.pk)
        self.assertIsNotNone(first)
        self.assertIsNone(second)
        self.assertEqual(ProjectCutModel.objects.filter(status="queued").count(), 1)
        self.assertEqual(len(sends), 1)

    def test_a_request_made_while_a_training_runs_queues_the_next_one(self):
        running = adaptation.request_training(self.project.pk)
        self.assertTrue(ProjectCutModel.objects.claim(running.pk, "worker-1"))
        waiting = adaptation.request_training(self.project.pk)
        self.assertNotEqual(waiting.pk, running.pk)
        self.assertEqual(waiting.status, "queued")


class OneAtATimeTestCase(AdaptationTestCase):
    def setUp(self):
        super().setUp()
        self.running = adaptation.request_training(self.project.pk)
        ProjectCutModel.objects.claim(self.running.pk, "worker-1")
        self.waiting = adaptation.request_training(self.project.pk)

    def test_it_does_not_start_a_training_while_another_of_the_project_runs(self):
        self.assertFalse(ProjectCutModel.objects.claim(self.waiting.pk, "worker-2"))
        self.assertEqual(ProjectCutModel.objects.get(pk=self.waiting.pk).status, "queued")

    def test_the_waiting_training_starts_once_the_running_one_ends(self):
        ProjectCutModel.objects.filter(pk=self.running.pk).update(status="ready", version=1)
        self.assertTrue(ProjectCutModel.objects.claim(self.waiting.pk, "worker-2"))

    def test_another_projects_training_is_not_held_up(self):
        other = adaptation.request_training(self.other_project.pk)
        self.assertTrue(ProjectCutModel.objects.claim(other.pk, "worker-2"))

    @override_settings(CUTROOM_CLAIM_TIMEOUT=60)
    def test_a_training_whose_worker_vanished_does_not_hold_up_the_next(self):
        ProjectCutModel.objects.filter(pk=self.running.pk).update(
            claimed_at=timezone.now() - timezone.timedelta(seconds=61))
        self.assertTrue(ProjectCutModel.objects.claim(self.waiting.pk, "worker-2"))

    def test_a_training_that_ends_sends_the_one_that_waited(self):
        # The project has nothing to learn from, so the running training fails at once.
        running = ProjectCutModel.objects.get(pk=self.running.pk)
        with self.captureOnCommitCallbacks() as sends:
            adaptation.train_project_model(running)
        self.assertEqual(ProjectCutModel.objects.get(pk=running.pk).status, "failed")
        self.assertEqual(len(sends), 1)

    def test_the_task_does_nothing_when_it_is_not_the_jobs_turn(self):
        tasks.retrain.apply(args=[self.waiting.pk], task_id="worker-2")
        self.assertEqual(ProjectCutModel.objects.get(pk=self.waiting.pk).status, "queued")


class FailedTrainingTestCase(AdaptationTestCase):
    def setUp(self):
        super().setUp()
        self.v1 = self.trained(1)
        # Its stored original is not a readable BVH file.
        self.capture = self.ready_capture(name="broken.bvh")
        commit(self.submit_review(self.capture, self.bob))
        self.job = ProjectCutModel.objects.get(status="queued")

    def train(self):
        tasks.retrain.apply(args=[self.job.pk], task_id="worker-1")
        self.job.refresh_from_db()

    def test_it_stores_why_training_failed_naming_the_take(self):
        self.train()
        self.assertEqual((self.job.status, self.job.version), ("failed", None))
        self.assertIn("training:", self.job.error)
        self.assertIn("broken", self.job.error)

    def test_detection_keeps_the_previous_model(self):
        self.train()
        self.assertEqual(ProjectCutModel.objects.newest(self.project.pk), self.v1)

    def test_the_review_page_shows_why(self):
        self.train()
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.capture.pk}/review/").json()["adaptation"]
        self.assertIn("broken", adapted["training_error"])
        self.assertEqual(adapted["project_model"],
                         {"version": 1, "n_takes": 2, "n_cuts": 6, "held_out": None})

    def test_a_later_successful_state_clears_the_failure_note(self):
        self.train()
        self.trained(2)
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.capture.pk}/review/").json()["adaptation"]
        self.assertIsNone(adapted["training_error"])


class ExamplesTestCase(AdaptationTestCase):
    def test_a_reviewed_take_gives_its_kept_cuts(self):
        capture = self.ready_capture(candidates=(100, 200, 300))
        self.submit_review(capture, self.bob, keep={100, 300})
        self.assertEqual(adaptation.project_examples(self.project.pk), [(capture, [100, 300])])

    def test_the_gold_version_wins_over_the_reviews(self):
        capture = self.ready_capture(candidates=(100, 200, 300))
        self.submit_review(capture, self.bob)
        gold.do_save_gold(capture, self.rachel, [120, 250], ["walk", "punch", None], 0)
        self.assertEqual(adaptation.project_examples(self.project.pk), [(capture, [120, 250])])

    def test_a_take_reviewed_twice_is_one_example_keeping_the_cuts_either_made(self):
        # Two reviews: a cut one of them made has the support of half of them.
        capture = self.ready_capture(candidates=(100, 300, 500), n_frames=700)
        self.submit_review(capture, self.bob, keep={100})
        self.submit_review(capture, self.rachel, keep={300})
        self.assertEqual(adaptation.project_examples(self.project.pk), [(capture, [100, 300])])

    def test_one_under_cutting_annotator_among_three_removes_no_cut(self):
        capture = self.ready_capture(candidates=(100, 300, 500), n_frames=700)
        self.submit_review(capture, self.bob)
        self.submit_review(capture, self.alice, keep=set())
        self.submit_review(capture, self.rachel)
        self.assertEqual(adaptation.project_examples(self.project.pk), [(capture, [100, 300, 500])])

    def test_a_cut_only_one_of_three_annotators_kept_is_left_out(self):
        capture = self.ready_capture(candidates=(100, 300, 500), n_frames=700)
        self.submit_review(capture, self.bob, keep={300})
        self.submit_review(capture, self.alice, keep={100, 300})
        self.submit_review(capture, self.rachel, keep={300, 500})
        self.assertEqual(adaptation.project_examples(self.project.pk), [(capture, [300])])

    def test_reviews_in_progress_do_not_count(self):
        self.login(self.bob)
        self.client.post(f"/api/captures/{self.ready_capture().pk}/review/")
        self.assertEqual(adaptation.project_examples(self.project.pk), [])

    def test_a_project_with_nothing_reviewed_fails_its_training_saying_so(self):
        job = adaptation.request_training(self.project.pk)
        tasks.retrain.apply(args=[job.pk], task_id="worker-1")
        job.refresh_from_db()
        self.assertEqual(job.status, "failed")
        self.assertIn("no submitted review or gold version", job.error)


class StaleTrainingTestCase(AdaptationTestCase):
    def setUp(self):
        super().setUp()
        self.job = adaptation.request_training(self.project.pk)
        ProjectCutModel.objects.filter(pk=self.job.pk).update(
            status="processing", claim_token="dead", attempts=1,
            claimed_at=timezone.now() - timezone.timedelta(hours=2))

    def test_the_sweep_requeues_a_training_whose_worker_vanished(self):
        with self.captureOnCommitCallbacks() as sends:
            self.assertEqual(jobs.sweep(), 1)
        self.assertEqual(ProjectCutModel.objects.get(pk=self.job.pk).status, "queued")
        self.assertEqual(len(sends), 1)

    def test_it_fails_it_instead_when_a_newer_training_waits(self):
        waiting = adaptation.request_training(self.project.pk)
        with self.captureOnCommitCallbacks() as sends:
            jobs.sweep()
        job = ProjectCutModel.objects.get(pk=self.job.pk)
        self.assertEqual(job.status, "failed")
        self.assertIn("keeps its previous model", job.error)
        self.assertEqual(ProjectCutModel.objects.get(pk=waiting.pk).status, "queued")
        self.assertEqual(len(sends), 1)


class TimeLimitTrainingTestCase(AdaptationTestCase):
    """A training killed at its hard time limit (with a real worker:
    tests/segmentation/integration/test_job_recovery.py)."""

    def setUp(self):
        super().setUp()
        self.v1 = self.trained(1)
        self.capture = self.ready_capture()
        commit(self.submit_review(self.capture, self.bob))
        self.running = ProjectCutModel.objects.get(status="queued")
        ProjectCutModel.objects.claim(self.running.pk, "worker-1")
        self.waiting = adaptation.request_training(self.project.pk)

    def test_it_fails_at_once_naming_the_limit_and_sends_the_one_that_waited(self):
        with self.captureOnCommitCallbacks() as sends:
            self.assertTrue(jobs.fail_at_time_limit(adaptation.RETRAIN, self.running.pk, "worker-1"))
        job = ProjectCutModel.objects.get(pk=self.running.pk)
        self.assertEqual((job.status, job.version, job.attempts), ("failed", None, 1))
        self.assertTrue(job.error.startswith(
            "Training stopped after its time limit of 600 s (CUTROOM_RETRAIN_TIME_LIMIT)"), job.error)
        self.assertIn("not retried", job.error)
        self.assertTrue(job.error_permanent)  # the same examples would take as long again
        self.assertIsNotNone(job.finished_at)
        self.assertEqual(len(sends), 1)
        self.assertEqual(ProjectCutModel.objects.get(pk=self.waiting.pk).status, "queued")

    def test_the_project_keeps_its_model_and_the_review_page_says_why(self):
        jobs.fail_at_time_limit(adaptation.RETRAIN, self.running.pk, "worker-1")
        self.assertEqual(ProjectCutModel.objects.newest(self.project.pk), self.v1)
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.capture.pk}/review/").json()["adaptation"]
        self.assertIn("(CUTROOM_RETRAIN_TIME_LIMIT)", adapted["training_error"])
        self.assertEqual(adapted["project_model"]["version"], 1)

    def test_it_leaves_alone_a_training_another_claim_holds(self):
        ProjectCutModel.objects.filter(pk=self.running.pk).update(claim_token="worker-2")
        with self.captureOnCommitCallbacks() as sends:
            self.assertFalse(jobs.fail_at_time_limit(adaptation.RETRAIN, self.running.pk, "worker-1"))
        self.assertEqual(ProjectCutModel.objects.get(pk=self.running.pk).status, "processing")
        self.assertEqual(sends, [])


class CutModelsEndpointTestCase(AdaptationTestCase):
    def test_members_see_the_projects_trainings_newest_first_with_failures_explained(self):
        self.trained(1)
        ProjectCutModel.objects.create(project=self.project, status="failed", error="training: x")
        self.login(self.bob)
        rows = self.client.get(f"/api/projects/{self.project.pk}/cut-models/").json()
        self.assertEqual([(r["version"], r["status"], r["error"]) for r in rows],
                         [(None, "failed", "training: x"), (1, "ready", None)])

    def test_an_outsider_gets_404(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get(f"/api/projects/{self.project.pk}/cut-models/").status_code, 404)

    def test_the_admin_lists_and_shows_trainings(self):
        from django.contrib.auth import get_user_model

        job = self.trained(1)
        self.client.force_login(get_user_model().objects.create_superuser("root", password="root-pw"))
        self.assertEqual(self.client.get("/admin/segmentation/projectcutmodel/").status_code, 200)
        page = self.client.get(f"/admin/segmentation/projectcutmodel/{job.pk}/change/")
        self.assertEqual(page.status_code, 200)


class SweepCommandTestCase(AdaptationTestCase):
    def test_the_command_requeues_a_training_whose_worker_vanished(self):
        from io import StringIO

        from django.core.management import call_command

        job = adaptation.request_training(self.project.pk)
        ProjectCutModel.objects.filter(pk=job.pk).update(
            status="processing", claim_token="dead", attempts=1,
            claimed_at=timezone.now() - timezone.timedelta(hours=2))
        out = StringIO()
        call_command("sweep_claims", stdout=out)
        self.assertEqual(out.getvalue().strip(), "1 stale job(s) requeued or failed")
        self.assertEqual(ProjectCutModel.objects.get(pk=job.pk).status, "queued")


class ExhaustedTrainingTestCase(AdaptationTestCase):
    @override_settings(CUTROOM_MAX_ATTEMPTS=2)
    def test_a_training_that_keeps_killing_its_worker_fails_and_the_next_one_is_sent(self):
        job = adaptation.request_training(self.project.pk)
        ProjectCutModel.objects.filter(pk=job.pk).update(status="processing", attempts=2, claim_token="x")
        waiting = ProjectCutModel.objects.create(project=self.project)
        with self.captureOnCommitCallbacks() as sends:
            tasks.retrain.apply(args=[job.pk], task_id="x")
        job.refresh_from_db()
        self.assertEqual(job.status, "failed")
        self.assertIn("started 3 times and never finished", job.error)
        self.assertIn("keeps its previous model", job.error)
        self.assertEqual(len(sends), 1)
        self.assertEqual(ProjectCutModel.objects.get(pk=waiting.pk).status, "queued")
