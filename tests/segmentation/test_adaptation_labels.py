"""Segments arrive labelled: a project trained on labelled reviews proposes, for every
segment of a new detection, the label its frame model finds most likely, with its
probability; a rename keeps the proposal (labels by id) and a retired label is proposed
no more. Jobs run in-process here."""

from motionlib import synth
from segmentation import services, tasks
from segmentation.models import ProjectCutModel
from segmentation.services import taxonomy
from segmentation.similar.proposals import MIN_PROBABILITY
from tests.segmentation.test_adaptation_detect import SECONDS, ReviewedTakesTestCase


class LabelledDetectionTestCase(ReviewedTakesTestCase):
    def review_to_the_truth(self, capture, seed):
        """Cut at the true boundaries and label every segment with its true action."""
        _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
        for _, _, label in segments:
            if not self.project.labels.filter(name=label).exists():
                services.do_add_label(self.project, label)
        review = services.get_or_create_review(capture, self.bob)
        for cut in list(review.cuts.all()):
            services.do_change_cut(review, self.bob, cut, review.version, fate="deleted")
        for start, _stop, _label in segments[1:]:
            services.do_insert_cut(review, self.bob, start, review.version)
        for index, (_, _, label) in enumerate(segments):
            services.do_label_segment(review, self.bob, index, label, review.version)
        with self.captureOnCommitCallbacks(execute=False) as callbacks:
            services.do_submit_review(review, self.bob, review.version)
        for callback in callbacks:
            callback()

    def redetect(self, capture):
        run = services.do_redetect(capture, self.alice)
        tasks.detect(run.pk)  # in-process, as a worker would
        run.refresh_from_db()
        self.assertEqual(run.status, "ready", run.error)
        return run

    def test_a_detection_after_training_returns_labelled_segments(self):
        model = self.train([92, 93])
        self.assertTrue(model.labels_model)
        run = self.ingested(seed=94).latest_run()
        self.assertEqual((run.status, run.model_version), ("ready", 1), run.error)
        self.assertEqual(len(run.proposals), len(run.candidates) + 1)
        ids = set(self.project.labels.values_list("id", flat=True))
        labelled = [p for p in run.proposals if p["label"] is not None]
        self.assertTrue(labelled)
        for proposal in labelled:
            self.assertIn(proposal["label"], ids)
            self.assertTrue(0 < proposal["probability"] <= 1)
        # the API gives them with the run
        self.login(self.alice)
        got = self.client.get(f"/api/captures/{run.capture_id}/runs/").json()
        self.assertEqual(next(r for r in got if r["id"] == run.pk)["proposals"], run.proposals)

    def test_a_rename_keeps_the_proposals_and_a_retired_label_is_proposed_no_more(self):
        self.train([92, 93])
        capture = self.ingested(seed=94)
        first = capture.latest_run().proposals
        label_id = next(p["label"] for p in first if p["label"] is not None)
        label = self.project.labels.get(pk=label_id)
        taxonomy.do_change_label(label, name="renamed action")
        again = self.redetect(capture)
        self.assertEqual([p["label"] for p in again.proposals], [p["label"] for p in first])
        taxonomy.do_change_label(label, retired=True)
        last = self.redetect(capture)
        self.assertNotIn(label_id, [p["label"] for p in last.proposals])
        self.assertTrue(ProjectCutModel.objects.filter(project=self.project, version=1).exists())

    def test_the_review_page_suggests_the_proposed_label_of_an_untouched_segment(self):
        self.train([92, 93])
        capture = self.ingested(seed=94)
        run = capture.latest_run()
        names = dict(self.project.labels.values_list("id", "name"))
        frames = [c["frame"] for c in run.candidates]
        bounds = [0, *frames, capture.n_frames]
        expected = {(a, b): (names[p["label"]], p["probability"]) for a, b, p in
                    zip(bounds[:-1], bounds[1:], run.proposals, strict=True)
                    if p["label"] and p["probability"] >= MIN_PROBABILITY}
        self.assertTrue(expected)
        self.login(self.rachel)  # a reviewer: she sees every review, so the run's proposals
        body = self.client.get(f"/api/captures/{capture.pk}/review/suggestions/").json()
        got = {(s["start"], s["stop"]): (s["label"], s["probability"])
               for s in body["suggestions"] if s["proposed"]}
        for span, label in expected.items():
            self.assertEqual(got.get(span), label)
