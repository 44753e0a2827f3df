"""Which detector a run uses: the project's newest learnt model for the ``default``
method, the zero-shot detector before any training, the registry's segmenter for other
methods. Jobs run in-process here; with real workers see
tests/segmentation/integration/test_adaptation_flow.py."""

from django.core.files.base import ContentFile

from motionlib import adapt, synth
from segmentation import services, tasks
from segmentation.files import takecache
from segmentation.files.takecache import StoredStudies
from segmentation.models import DetectionRun, ProjectCutModel
from segmentation.services import adaptation
from tests.segmentation.base import BaseTestCase, synthetic_bvh

SECONDS = 30.0
FORMAT_1_MODELS = [
    ('{"format": 1, "min_segment_s": 0.85, "n_cuts": 8, "n_takes": 2, "offset_s": 0.0, '
     '"placement": "onset", "prominence": 0.1, "scale_max_s": 6.0, "scale_min_s": 3.0, '
     '"threshold": 0.1}',
     98, [922, 1448, 1898, 2586, 3085], [0.6575, 0.8871, 0.8344, 0.7624, 0.782]),
    ('{"format": 1, "min_segment_s": 1.125, "n_cuts": 51, "n_takes": 3, "offset_s": 0.0, '
     '"placement": "split", "prominence": 0.1, "scale_max_s": 3.0, "scale_min_s": 1.5, '
     '"threshold": 0.1}',
     99, [770, 1458, 2246, 3006, 3398], [0.8602, 0.8618, 0.8865, 0.9149, 0.5838]),
]


class ReviewedTakesTestCase(BaseTestCase):
    """Synthetic takes ingested for real, reviewed to their true boundaries, trained on."""

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
        return self.run_training(ProjectCutModel.objects.get(project=self.project, status="queued"))

    def run_training(self, job):
        """Run the training ``job`` in-process; it must succeed."""
        tasks.retrain(job.pk)
        job.refresh_from_db()
        self.assertEqual(job.status, "ready", job.error)
        return job


class DetectionWithModelTestCase(ReviewedTakesTestCase):
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

    def test_a_model_stored_in_the_first_format_still_detects_as_it_did(self):
        # Models as format 1 stored them, read from their row, cut a take where they cut it
        # when format-1 models were still learnt: the one the release v0.2.0 stored
        # (upgrade/v0.2.0.sqlite), and one learnt from short activities, which cuts
        # elsewhere than the zero-shot detector.
        for version, (text, seed, frames, confidence) in enumerate(FORMAT_1_MODELS, start=1):
            ProjectCutModel.objects.create(project=self.project, status="ready",
                                           version=version, model=text, n_takes=2, n_cuts=8)
            run = self.ingested(seed=seed).latest_run()
            self.assertEqual((run.status, run.model_version), ("ready", version), run.error)
            self.assertEqual([c["frame"] for c in run.candidates], frames)
            self.assertEqual([round(c["confidence"], 4) for c in run.candidates], confidence)

    def test_other_methods_ignore_the_model(self):
        self.train([95])
        capture = self.ingested(seed=96)
        run = services.do_start_run(capture, self.alice, "bone_angle", {})
        tasks.detect(run.pk)
        run = DetectionRun.objects.get(pk=run.pk)
        self.assertEqual((run.status, run.model_version), ("ready", None), run.error)


class TrainingErrorTestCase(ReviewedTakesTestCase):
    def test_a_reviewed_take_whose_stored_file_is_gone_is_named_when_nothing_else_can_be_learnt(self):
        capture = self.ingested(seed=97)
        self.review_to_the_truth(capture, 97)
        storage = capture.original.storage
        for name in (capture.original.name, *takecache.cache_names(capture)):
            storage.delete(name)
        job = ProjectCutModel.objects.get(project=self.project, status="queued")
        tasks.retrain(job.pk)
        job.refresh_from_db()
        self.assertEqual(job.status, "failed")
        self.assertEqual(job.error, f"training: no reviewed take can be learnt from: capture {capture.pk} "
                                    f"('take_97.bvh') skipped: cannot be read: take_97.bvh: no such file")
        # Annotators read this on the review page: no server folder in it.
        self.assertNotIn(capture.original.name, job.error)


class StoredStudiesTestCase(ReviewedTakesTestCase):
    """What a training learnt from each reviewed take is stored, so a retraining after
    one more submit reads and analyses only what changed, and learns the same model."""

    def retrain(self):
        return self.run_training(adaptation.request_training(self.project.pk))

    def fresh_model(self):
        """The model fitted from the takes themselves, nothing stored."""
        examples = adaptation.project_examples(self.project.pk)
        return adapt.fit_cut_model([(adaptation.example_take(c), cuts) for c, cuts in examples])

    def test_a_refit_reads_no_take_whose_study_is_stored(self):
        # The training's fit; its gate then detects on the takes it scores (model_gate).
        first = self.train([81, 82])
        examples = adaptation.project_examples(self.project.pk)
        storage = examples[0][0].original.storage
        for capture, _cuts in examples:
            self.assertTrue(storage.exists(StoredStudies.name(takecache.example_key(capture))))
            # Without its original and its parsed copy, a take that had to be read would
            # fail the fit.
            for name in (capture.original.name, *takecache.cache_names(capture)):
                storage.delete(name)
        again = adaptation.fit_examples(examples, StoredStudies(storage))
        self.assertEqual(again.to_json(), first.model)

    def test_a_retraining_on_the_same_examples_is_accepted_as_the_next_version(self):
        first = self.train([81, 82])
        again = self.retrain()
        self.assertEqual((again.version, again.model, again.refused), (first.version + 1, first.model, ""))

    def test_a_take_reviewed_again_keeps_its_study_and_the_model_is_as_learnt_afresh(self):
        # A study holds the take's candidates and their evidence, which do not depend on
        # where people cut: new cuts on the same take change the model, not the study.
        self.train([83, 84])
        capture, cuts = adaptation.project_examples(self.project.pk)[0]
        name = StoredStudies.name(takecache.example_key(capture))
        storage = capture.original.storage
        with storage.open(name, "rb") as handle:
            before = handle.read()
        review = services.get_or_create_review(capture, self.rachel)
        for cut in list(review.cuts.all()):
            if cut.frame == cuts[0]:
                services.do_change_cut(review, self.rachel, cut, review.version, fate="deleted")
        services.do_submit_review(review, self.rachel, review.version)
        job = self.retrain()
        with storage.open(name, "rb") as handle:
            self.assertEqual(handle.read(), before)
        self.assertEqual(adapt.CutModel.from_json(job.model), self.fresh_model())

    def test_an_unreadable_stored_study_is_made_again(self):
        first = self.train([85])
        capture, _ = adaptation.project_examples(self.project.pk)[0]
        name = StoredStudies.name(takecache.example_key(capture))
        storage = capture.original.storage
        storage.delete(name)
        storage.save(name, ContentFile(b"not a zip file"))
        again = self.retrain()
        self.assertEqual(again.model, first.model)
        with storage.open(name, "rb") as handle:
            self.assertTrue(handle.read().startswith(b"PK"))
