"""The gate a newly trained cut model passes: it replaces the project's model only when it
is not worse on reviewed takes neither model learnt from; a refused model is kept with
the reason, and the review page shows each model's own figure and why the last one was
refused. Synthetic takes are uploaded and ingested for real and trainings run in-process
(with real workers: tests/segmentation/integration/test_adaptation_flow.py)."""

from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile

from motionlib import adapt, metrics, synth
from segmentation import services, tasks
from segmentation.models import ProjectCutModel
from segmentation.services import model_gate
from tests.segmentation.base import BaseTestCase, ingested, synthetic_bvh

SECONDS = 30.0


def true_cuts(seed):
    _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
    return [start for start, _stop, _label in segments[1:]]


class GateTestCase(BaseTestCase):
    """Takes uploaded, reviewed and trained on once per class (each costs a detection)."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.dave = get_user_model().objects.create_user("dave", password="dave-password")
        services.do_set_member(cls.project, "dave", "annotator")

    @classmethod
    def ingested(cls, seed):
        upload = SimpleUploadedFile(f"take_{seed}.bvh", synthetic_bvh(seed=seed, duration=SECONDS))
        return ingested(cls.project, cls.alice, upload)

    @classmethod
    def reviewed(cls, seeds, user, truthful=True):
        """``user`` deletes every candidate of each take, inserts its true cuts (none when
        not ``truthful``) and submits (the training it asks for on commit is not sent)."""
        captures = []
        for seed in seeds:
            capture = cls.ingested(seed)
            review = services.get_or_create_review(capture, user)
            for cut in list(review.cuts.all()):
                services.do_change_cut(review, user, cut, review.version, fate="deleted")
            for frame in true_cuts(seed) if truthful else []:
                services.do_insert_cut(review, user, frame, review.version)
            services.do_submit_review(review, user, review.version)
            captures.append(capture)
        return captures

    @classmethod
    def train(cls):
        """Run one training of the project in-process; it must end ready (accepted or not)."""
        job = ProjectCutModel.objects.create(project=cls.project)
        tasks.retrain(job.pk)
        job.refresh_from_db()
        assert job.status == "ready", job.error
        return job


class RefusedModelTestCase(GateTestCase):
    """bob reviews two takes to their true cuts (model v1); then dave, an annotator who
    under-cuts, deletes every candidate of five more takes and inserts nothing: a model
    learnt from all seven proposes nothing on the next take."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.bobs = cls.reviewed([11, 12], cls.bob)
        cls.v1 = cls.train()
        cls.daves = cls.reviewed([13, 14, 15, 17, 18], cls.dave, truthful=False)
        cls.job = cls.train()
        cls.next = cls.ingested(16)

    def test_it_refuses_the_model_and_the_current_one_stays(self):
        self.assertEqual(self.v1.version, 1)
        self.assertEqual((self.job.version, self.job.n_takes), (None, 7))
        self.assertEqual(ProjectCutModel.objects.newest(self.project.pk).pk, self.v1.pk)

    def test_the_refused_model_would_cut_the_next_take_worse(self):
        take, _segments = synth.generate(seed=16, fps=120.0, duration=SECONDS)
        truth = true_cuts(16)

        def f1(row):
            found = adapt.detect(take, adapt.CutModel.from_json(row.model)).cuts
            return metrics.boundary_scores(found, truth, fps=120.0, tolerance_s=1.0)["f1"]

        self.assertLess(f1(self.job), f1(self.v1) - 0.3)

    def test_it_stores_why_naming_both_figures_on_the_takes_the_current_model_learnt_from(self):
        self.assertTrue(self.job.refused.startswith(
            "refused: on 2 held-out reviewed takes that the current model v1 learnt from it needs "), self.job.refused)
        self.assertIn("edits per true cut (F1 ", self.job.refused)
        self.assertIn(", the current model ", self.job.refused)

    def test_the_next_upload_detects_with_the_current_model(self):
        run = self.next.latest_run()
        self.assertEqual((run.model_version, run.model_n_takes), (1, 2))
        self.assertTrue(run.candidates)

    def test_the_review_page_says_why_and_which_model_is_kept(self):
        self.login(self.rachel)
        adapted = self.client.get(f"/api/captures/{self.next.pk}/review/").json()["adaptation"]
        self.assertEqual(adapted["training_refused"], self.job.refused)
        self.assertIsNone(adapted["training_error"])
        self.assertEqual(adapted["project_model"]["version"], 1)

    def test_an_annotators_review_page_leaves_the_refusal_to_reviewers_and_admins(self):
        """The gate's refusal is news for those who look after the project's model, not
        something an annotator can act on, on every take they open."""
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.next.pk}/review/").json()["adaptation"]
        self.assertIsNone(adapted["training_refused"])
        self.assertEqual(adapted["project_model"]["version"], 1)

    def test_the_project_lists_the_refused_training_with_its_reason(self):
        self.login(self.dave)
        rows = self.client.get(f"/api/projects/{self.project.pk}/cut-models/").json()
        self.assertEqual([(r["version"], r["status"], r["refused"]) for r in rows],
                         [(None, "ready", self.job.refused), (1, "ready", "")])


class AcceptedModelTestCase(GateTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.bobs = cls.reviewed([21, 22], cls.bob)
        cls.v1 = cls.train()
        cls.next = cls.ingested(24)

    def test_the_first_model_is_scored_on_each_take_by_a_model_fitted_without_it(self):
        self.assertEqual((self.v1.version, self.v1.refused), (1, ""))
        self.assertEqual(self.v1.trained_on, [c.pk for c in self.bobs])
        self.assertEqual(self.v1.held_out_takes, 2)
        self.assertGreaterEqual(self.v1.held_out_edits_per_cut, 0.0)
        self.assertTrue(0.0 <= self.v1.held_out_f1 <= 1.0)

    def test_the_review_page_shows_the_models_own_figure(self):
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.next.pk}/review/").json()["adaptation"]
        figure = {"n_takes": 2, "edits_per_cut": self.v1.held_out_edits_per_cut, "f1": self.v1.held_out_f1}
        self.assertEqual((adapted["model_version"], adapted["held_out"]), (1, figure))
        self.assertEqual(adapted["project_model"]["held_out"], figure)
        self.assertIsNone(adapted["training_refused"])

    def test_an_outsider_sees_neither_the_page_nor_the_models(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get(f"/api/captures/{self.next.pk}/review/").status_code, 404)
        self.assertEqual(self.client.get(f"/api/projects/{self.project.pk}/cut-models/").status_code, 404)


class GrowingModelTestCase(GateTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.bobs = cls.reviewed([21, 22], cls.bob)
        cls.v1 = cls.train()
        cls.more = cls.reviewed([23], cls.rachel)
        cls.v2 = cls.train()

    def test_a_model_with_one_more_take_reviewed_alike_replaces_it(self):
        self.assertEqual((self.v2.version, self.v2.refused, self.v2.n_takes), (2, "", 3))
        self.assertEqual(self.v2.trained_on, [c.pk for c in [*self.bobs, *self.more]])
        self.assertEqual(ProjectCutModel.objects.newest(self.project.pk).pk, self.v2.pk)

    def test_it_is_scored_on_every_reviewed_take(self):
        self.assertEqual(self.v2.held_out_takes, 3)


class ScoredTakesTestCase(BaseTestCase):
    """Which reviewed takes a training scores (no take is read here)."""

    def examples(self, n):
        class Capture:
            def __init__(self, pk):
                self.pk = pk

        return [(Capture(pk), []) for pk in range(1, n + 1)]

    def scored(self, n, learnt):
        return [c.pk for c, _ in model_gate.scored_takes(self.examples(n), set(learnt))]

    def test_it_scores_every_take_up_to_the_limit_newest_first(self):
        self.assertEqual(self.scored(3, []), [3, 2, 1])
        self.assertEqual(self.scored(14, []), list(range(14, 4, -1)))

    def test_it_keeps_half_the_places_for_the_takes_the_current_model_learnt_from(self):
        self.assertEqual(self.scored(20, range(1, 11)), [20, 19, 18, 17, 16, 10, 9, 8, 7, 6])

    def test_a_group_with_fewer_takes_leaves_its_places_to_the_other(self):
        self.assertEqual(self.scored(12, [1, 2]), [12, 11, 10, 9, 8, 7, 6, 5, 2, 1])
        self.assertEqual(self.scored(12, range(1, 12)), [12, 11, 10, 9, 8, 7, 6, 5, 4, 3])


class FigureTestCase(BaseTestCase):
    """How the gate compares two models' figures (model_gate.Figure)."""

    def figure(self, *takes):
        figure = model_gate.Figure()
        for found, truth in takes:
            figure.add(found, truth, 120.0)
        return figure

    def test_edits_and_f1_are_pooled_over_the_takes_cuts(self):
        # Take 1: 3 of 4 true cuts found, one insert; take 2: one extra candidate, a delete.
        figure = self.figure(([100, 500, 900], [100, 500, 900, 1300]), ([200, 800], [200]))
        self.assertEqual((figure.takes, figure.edits, figure.true_cuts), (2, 2, 5))
        self.assertAlmostEqual(figure.edits_per_cut, 0.4)
        self.assertAlmostEqual(figure.f1, 2 * 0.8 * 0.8 / 1.6)

    def test_a_take_without_true_cuts_counts_its_candidates_as_deletes(self):
        self.assertEqual(self.figure(([100, 500], [])).edits_per_cut, 2.0)
        self.assertEqual(self.figure(([], [])).f1, 1.0)

    def test_more_edits_per_cut_is_worse(self):
        truth = [100, 500, 900, 1300]
        current = self.figure(([100, 500, 900, 1300], truth))
        self.assertFalse(self.figure(([100, 500, 900], truth)).not_worse_than(current))

    def test_fewer_edits_with_an_f1_a_little_lower_is_not_worse(self):
        truth = [100 + 400 * i for i in range(20)]
        # The current model finds every cut but places 10 of them 0.5 s late (10 moves);
        # the candidate places 19 exactly and misses one (one insert).
        current = self.figure(([t + (60 if i < 10 else 0) for i, t in enumerate(truth)], truth))
        candidate = self.figure((truth[:-1], truth))
        self.assertLess(candidate.f1, current.f1)
        self.assertTrue(candidate.not_worse_than(current))

    def test_an_f1_much_lower_is_worse_whatever_the_edits(self):
        truth = [100 + 400 * i for i in range(10)]
        # The current model finds all ten, nine of them 0.5 s late (nine moves); the
        # candidate finds eight exactly (two inserts): fewer edits, F1 0.11 lower.
        current = self.figure(([t + (60 if i else 0) for i, t in enumerate(truth)], truth))
        candidate = self.figure((truth[:8], truth))
        self.assertLess(candidate.edits_per_cut, current.edits_per_cut)
        self.assertFalse(candidate.not_worse_than(current))
