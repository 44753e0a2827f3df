"""Which detector a run uses: the project's newest learnt model for the ``default``
method, the zero-shot detector before any training, the registry's segmenter for other
methods. Jobs run in-process here; with real workers see
tests/segmentation/integration/test_adaptation_flow.py."""

from motionlib import synth
from segmentation import services, tasks
from segmentation.models import DetectionRun, ProjectCutModel
from tests.segmentation.base import BaseTestCase, synthetic_bvh

SECONDS = 30.0


class DetectionWithModelTestCase(BaseTestCase):
    def ingested(self, seed):
        self.login(self.alice)
        response = self.upload(synthetic_bvh(seed=seed, duration=SECONDS), name=f"take_{seed}.bvh")
        capture = self.ingest(response.json()["id"])
        self.assertEqual(capture.status, "ready", capture.error)
        return capture

    def review_to_the_truth(self, capture, seed):
        _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
        review = services.get_or_create_review(capture, self.bob)
        for cut in list(review.cuts.all()):
            services.do_change_cut(review, self.bob, cut, review.version, fate="deleted")
        for start, _stop, _label in segments[1:]:
            services.do_insert_cut(review, self.bob, start, review.version)
        with self.captureOnCommitCallbacks(execute=False) as callbacks:
            services.do_submit_review(review, self.bob, review.version)
        for callback in callbacks:
            callback()

    def train(self, seeds):
        for seed in seeds:
            self.review_to_the_truth(self.ingested(seed), seed)
        job = ProjectCutModel.objects.get(project=self.project, status="queued")
        tasks.retrain(job.pk)
        job.refresh_from_db()
        self.assertEqual(job.status, "ready", job.error)
        return job

    def test_a_project_without_a_model_detects_zero_shot(self):
        run = self.ingested(seed=91).latest_run()
        self.assertEqual((run.status, run.method), ("ready", "default"))
        self.assertEqual((run.model_version, run.model_n_takes), (None, None))

    def test_a_default_run_detects_with_the_newest_model_and_records_it(self):
        model = self.train([92, 93])
        run = self.ingested(seed=94).latest_run()
        self.assertEqual((model.version, model.n_takes), (1, 2))
        self.assertEqual((run.status, run.model_version, run.model_n_takes), ("ready", 1, 2), run.error)
        self.assertTrue(run.candidates)

    def test_other_methods_ignore_the_model(self):
        self.train([95])
        capture = self.ingested(seed=96)
        run = services.do_start_run(capture, self.alice, "bone_angle", {})
        tasks.detect(run.pk)
        run = DetectionRun.objects.get(pk=run.pk)
        self.assertEqual((run.status, run.model_version), ("ready", None), run.error)
