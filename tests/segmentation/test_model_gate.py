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
from segmentation.services import adaptation, model_gate
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


def f1_on(seed, row):
    """F1 within 1 s of a stored model (None: zero-shot) on synthetic take ``seed``."""
    take, _segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
    model = adapt.CutModel.from_json(row.model) if row is not None else None
    found = adapt.detect(take, model).cuts
    return metrics.boundary_scores(found, true_cuts(seed), fps=120.0, tolerance_s=1.0)["f1"], len(found)


class UnderCuttingLaterTestCase(GateTestCase):
    """bob reviews two takes to their true cuts (model v1); then dave, an annotator who
    under-cuts, deletes every candidate of five more takes and inserts nothing. His takes
    keep no cut where the zero-shot detector proposes many: they are not learnt from (the
    gate still scores on them), so the project's model goes on cutting the next take as
    v1 does."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.bobs = cls.reviewed([11, 12], cls.bob)
        cls.v1 = cls.train()
        cls.daves = cls.reviewed([13, 14, 15, 17, 18], cls.dave, truthful=False)
        cls.job = cls.train()
        cls.next = cls.ingested(16)

    def test_the_model_in_use_cuts_the_next_take_as_well_as_v1(self):
        self.assertEqual(self.job.trained_on, [c.pk for c in self.bobs])
        in_use = ProjectCutModel.objects.newest(self.project.pk)
        self.assertGreaterEqual(f1_on(16, in_use)[0], f1_on(16, self.v1)[0] - 0.05)

    def test_the_next_upload_has_candidates(self):
        self.assertTrue(self.next.latest_run().candidates)

    def test_the_figure_says_it_was_measured_on_two_annotators_takes_alone(self):
        basis = self.job.held_out_basis
        self.assertEqual((basis["gold"], basis["shared"], basis["single"], basis["annotators"]), (0, 0, 7, 2))
        self.assertEqual(basis["true_cuts"], len(true_cuts(11)) + len(true_cuts(12)))


class FirstAnnotatorUnderCutsTestCase(GateTestCase):
    """Issue 48, item 3: dave under-cuts the first four reviewed takes of the project (he
    keeps no cut where the zero-shot detector proposes many): his takes count little, the
    project's model goes on proposing cuts, and bob's honest reviews that follow are
    learnt."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.daves = cls.reviewed([31, 32, 33, 34], cls.dave, truthful=False)
        cls.first = cls.train()
        cls.next = cls.ingested(36)
        cls.bobs = cls.reviewed([37, 38, 39], cls.bob)
        cls.second = cls.train()

    def test_the_model_learnt_from_daves_takes_alone_is_refused_saying_why(self):
        self.assertEqual((self.first.status, self.first.version), ("ready", None))
        self.assertEqual(self.first.refused, "refused: its 4 held-out takes were all reviewed by annotators whose "
                         "reviews keep far fewer or far more cuts than the zero-shot detector proposes there")

    def test_the_next_upload_detects_zero_shot_with_candidates(self):
        run = self.next.latest_run()
        self.assertIsNone(run.model_version)
        self.assertTrue(run.candidates)

    def test_the_honest_retraining_is_accepted_and_cuts_the_next_take(self):
        self.assertTrue(self.second.version, self.second.refused)
        f1, found = f1_on(36, self.second)
        self.assertGreater(found, 0)
        self.assertGreaterEqual(f1, f1_on(36, None)[0] - 0.05)

    def test_the_figure_says_it_was_measured_on_one_annotators_reviews_without_a_cut(self):
        self.assertEqual(self.first.held_out_basis,
                         {"gold": 0, "shared": 0, "single": 4, "annotators": 1, "true_cuts": 0})

    def test_the_review_page_shows_the_honest_model_with_what_its_figure_was_measured_on(self):
        self.login(self.bob)
        adapted = self.client.get(f"/api/captures/{self.next.pk}/review/").json()["adaptation"]
        self.assertEqual({k: adapted["project_model"]["held_out"][k] for k in ("single", "annotators")},
                         {"single": 7, "annotators": 2})


class OverCutterReReviewsTestCase(GateTestCase):
    """Issue 48, item 3: bob reviews four takes (model v1); dave re-reviews the same four,
    adding a cut in the middle of every segment. The two tie on each extra cut; the
    project's current model, which learnt from bob, settles the tie."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        cls.bobs = cls.reviewed([41, 42, 43, 44], cls.bob)
        cls.v1 = cls.train()
        for capture, seed in zip(cls.bobs, [41, 42, 43, 44], strict=True):
            review = services.get_or_create_review(capture, cls.dave)
            for cut in list(review.cuts.all()):
                services.do_change_cut(review, cls.dave, cut, review.version, fate="deleted")
            bounds = [0, *true_cuts(seed), capture.n_frames]
            over = sorted({*true_cuts(seed), *[(a + b) // 2 for a, b in zip(bounds[:-1], bounds[1:], strict=True)]})
            for frame in over:
                services.do_insert_cut(review, cls.dave, frame, review.version)
            services.do_submit_review(review, cls.dave, review.version)
        cls.pool = adaptation.project_pool(
            cls.project.pk, referee=adaptation.referee_for(adapt.CutModel.from_json(cls.v1.model)))
        cls.job = cls.train()

    def test_the_examples_are_bobs_cuts(self):
        examples, sources = self.pool
        self.assertEqual([cuts for _capture, cuts in examples], [true_cuts(s) for s in [41, 42, 43, 44]])
        self.assertEqual(set(sources.values()), {model_gate.SHARED})

    def test_without_a_referee_the_over_cutters_cuts_would_be_kept(self):
        examples = adaptation.project_examples(self.project.pk)
        self.assertGreater(sum(map(len, [cuts for _capture, cuts in examples])),
                           1.5 * sum(len(true_cuts(s)) for s in [41, 42, 43, 44]))

    def test_the_model_in_use_proposes_about_as_many_cuts_as_v1(self):
        in_use = ProjectCutModel.objects.newest(self.project.pk)
        (f1, found), (f1_v1, found_v1) = f1_on(45, in_use), f1_on(45, self.v1)
        self.assertLessEqual(found, found_v1 + 1)
        self.assertGreaterEqual(f1, f1_v1 - 0.05)


class SourcesDecideTestCase(BaseTestCase):
    """How the gate weighs the takes of each source (model_gate.judge, no take read): one
    annotator's takes never outvote the rest of the project."""

    class Capture:
        fps = 120.0

        def __init__(self, pk):
            self.pk = pk

    truth = [100 + 400 * i for i in range(10)]

    def judge(self, sources, candidate_right, current=None):
        """Each scored take's truth is ``truth``; the candidate proposes it exactly on the
        takes ``candidate_right`` holds, else nothing past the first two cuts; the rival
        proposes the truth (or the converse)."""
        examples = [(self.Capture(pk), self.truth) for pk in sources]

        def detect(capture, model):
            if model == "candidate" and not candidate_right(capture.pk):
                return self.truth[:2] + [t + 5 for t in self.truth[2:]] + [t + 200 for t in self.truth[2:]]
            if model == "current" and candidate_right(capture.pk):
                return self.truth[:2] + [t + 200 for t in self.truth[2:]]
            return self.truth

        return model_gate.judge(
            examples, current, "current" if current else None, sources=sources,
            candidate_without=lambda capture: "candidate",
            current_without=lambda capture: "current", detect=detect)

    def test_one_annotator_whose_takes_alone_favour_the_candidate_cannot_get_it_accepted(self):
        sources = {1: 7, 2: 7, 3: 7, 4: 8, 5: 8, 6: 8}  # annotator 7 vs annotator 8
        verdict = self.judge(sources, lambda pk: pk <= 3)
        self.assertTrue(verdict.refused.startswith("refused: on 3 held-out takes reviewed by one annotator alone"),
                        verdict.refused)

    def test_one_annotator_whose_takes_alone_disfavour_it_cannot_refuse_what_shared_takes_support(self):
        sources = {1: 7, 2: 7, 3: 7, 4: model_gate.SHARED, 5: model_gate.SHARED, 6: model_gate.SHARED,
                   7: model_gate.GOLD}
        self.assertEqual(self.judge(sources, lambda pk: pk > 3).refused, "")

    def test_a_candidate_worse_on_the_gold_versions_is_refused(self):
        sources = {1: 7, 2: 7, 3: 8, 4: 8, 5: model_gate.GOLD}
        verdict = self.judge(sources, lambda pk: pk != 5)
        self.assertIn("on 1 held-out take with a gold version it needs", verdict.refused)

    def test_a_candidate_that_proposes_nothing_where_zero_shot_proposes_cuts_is_refused(self):
        examples = [(self.Capture(pk), []) for pk in (1, 2, 3)]
        verdict = model_gate.judge(
            examples, None, None, sources={1: 7, 2: 7, 3: 7},
            candidate_without=lambda capture: "candidate", current_without=None,
            detect=lambda capture, model: [] if model == "candidate" else self.truth)
        self.assertEqual(verdict.refused, "refused: it proposes 0 cuts on 3 held-out reviewed takes where the "
                         "zero-shot detector proposes 30 (a model must propose between a quarter and 4 times as many)")

    def test_a_candidate_that_proposes_far_more_cuts_is_refused(self):
        examples = [(self.Capture(pk), self.truth) for pk in (1, 2)]
        many = list(range(10, 4000, 20))
        verdict = model_gate.judge(
            examples, None, None, sources={1: model_gate.SHARED, 2: model_gate.GOLD},
            candidate_without=lambda capture: "candidate", current_without=None,
            detect=lambda capture, model: many if model == "candidate" else self.truth)
        self.assertIn(f"it proposes {2 * len(many)} cuts on 2 held-out reviewed takes", verdict.refused)

    def test_the_basis_counts_each_source(self):
        sources = {1: 7, 2: 7, 3: 8, 4: model_gate.SHARED, 5: model_gate.GOLD}
        self.assertEqual(self.judge(sources, lambda pk: True).basis,
                         {"gold": 1, "shared": 1, "single": 3, "annotators": 2, "true_cuts": 50})


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
        figure = {"n_takes": 2, "edits_per_cut": self.v1.held_out_edits_per_cut, "f1": self.v1.held_out_f1,
                  "gold": 0, "shared": 0, "single": 2, "annotators": 1,
                  "true_cuts": len(true_cuts(21)) + len(true_cuts(22))}
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
