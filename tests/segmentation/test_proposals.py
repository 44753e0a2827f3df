"""An annotator's proposed labels come from their own submitted reviews and gold only
(issue 47): another annotator's labels never reach them, not through the review's
suggestions nor through the detection run's proposals, which only the project's reviewers
and admins are given. Jobs run in-process here."""

from motionlib import synth
from segmentation import services, tasks
from segmentation.models import LabelSuggestion
from segmentation.services.gold import do_save_gold
from segmentation.similar import proposals
from tests.segmentation.test_adaptation_detect import SECONDS, ReviewedTakesTestCase
from tests.segmentation.truth_reviews import review_to_the_truth

TRUE = set(synth.ACTIONS)


class ProposalsBase(ReviewedTakesTestCase):
    """bob and dora annotate; helpers to review, train and read what the page is offered."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        from django.contrib.auth import get_user_model

        cls.dora = get_user_model().objects.create_user("dora", password="dora-password")
        services.do_set_member(cls.project, "dora", "annotator")

    def review(self, capture, user, seed, name=lambda action: action):
        """``review_to_the_truth``, the submit's jobs run here."""
        with self.captureOnCommitCallbacks(execute=True):
            return review_to_the_truth(self.project, capture, user, seed, name)

    def bobs(self, action):
        return f"bob {action}"

    def trained_by_bob(self, seeds=(92, 93)):
        captures = [self.ingested(seed) for seed in seeds]
        for capture, seed in zip(captures, seeds, strict=True):
            self.review(capture, self.bob, seed, self.bobs)
        self.retrain()
        return captures

    def retrain(self):
        from segmentation.models import ProjectCutModel

        job = ProjectCutModel.objects.filter(project=self.project, status="queued").first()
        if job is not None:
            self.run_training(job)

    def offered(self, capture, user):
        """The suggestions the review page gets for ``user`` once the job has run."""
        self.login(user)
        url = f"/api/captures/{capture.pk}/review/suggestions/"
        self.client.get(url)
        tasks.suggest(capture.pk, user.pk)  # the worker's job, here
        body = self.client.get(url).json()
        self.assertFalse(body["pending"])
        return body["suggestions"]

    def proposed_labels(self, capture, user):
        return {s["label"] for s in self.offered(capture, user) if s["proposed"]}


class ProposalsTestCase(ProposalsBase):
    def test_another_annotators_labels_are_never_proposed_to_an_annotator(self):
        self.trained_by_bob()
        capture = self.ingested(seed=94)
        run = capture.latest_run()
        bobs = {self.bobs(a) for a in TRUE}
        names = dict(self.project.labels.values_list("id", "name"))
        # the run's proposals (learnt from bob's reviews) carry bob's labels ...
        self.assertTrue({names[p["label"]] for p in run.proposals if p["label"]} <= bobs)
        self.assertTrue(any(p["label"] for p in run.proposals))
        # ... which dora, who has no review nor gold to learn from, is never offered
        offered = self.offered(capture, self.dora)
        self.assertEqual([s for s in offered if s["label"]], [])
        self.assertFalse(LabelSuggestion.objects.filter(capture=capture, label__isnull=False)
                         .exclude(pool__startswith=proposals.PREFIX + "own").exists())

    def test_the_runs_api_gives_the_runs_proposals_to_reviewers_only(self):
        self.trained_by_bob()
        capture = self.ingested(seed=94)
        url = f"/api/captures/{capture.pk}/runs/"
        self.login(self.dora)
        self.assertEqual(self.client.get(url).json()[0]["proposals"], [])
        self.assertIsNone(self.client.get(f"/api/captures/{capture.pk}/").json()["latest_run"]
                          .get("proposals") or None)
        self.login(self.rachel)
        self.assertEqual(self.client.get(url).json()[0]["proposals"], capture.latest_run().proposals)

    def test_an_annotators_own_reviews_give_her_proposals_and_bobs_give_his(self):
        self.trained_by_bob()
        for seed in (95, 96):
            self.review(self.ingested(seed), self.dora, seed)
        capture = self.ingested(seed=94)
        hers = self.proposed_labels(capture, self.dora)
        self.assertTrue(hers)
        self.assertTrue(hers <= TRUE, hers)
        his = self.proposed_labels(capture, self.bob)
        self.assertTrue(his)
        self.assertTrue(his <= {self.bobs(a) for a in TRUE}, his)

    def test_gold_labels_reach_an_annotators_proposals(self):
        captures = self.trained_by_bob()
        for capture, seed in zip(captures, (92, 93), strict=True):
            _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
            for _, _, action in segments:
                if not self.project.labels.filter(name=action).exists():
                    services.do_add_label(self.project, action)
            with self.captureOnCommitCallbacks(execute=True):
                do_save_gold(capture, self.rachel, [s for s, _, _ in segments[1:]],
                             [a for _, _, a in segments], 0)
        capture = self.ingested(seed=94)
        hers = self.proposed_labels(capture, self.dora)
        self.assertTrue(hers)
        self.assertTrue(hers <= TRUE, hers)

    def test_a_proposal_is_kept_with_its_probability_and_not_asked_again(self):
        for seed in (95, 96):
            self.review(self.ingested(seed), self.dora, seed)
        capture = self.ingested(seed=94)
        offered = [s for s in self.offered(capture, self.dora) if s["proposed"]]
        self.assertTrue(offered)
        for s in offered:
            self.assertTrue(0 < s["probability"] <= 1)
        rows = list(LabelSuggestion.objects.filter(capture=capture, pool__startswith=proposals.PREFIX)
                    .values_list("pk", flat=True))
        tasks.suggest(capture.pk, self.dora.pk)  # the spans have theirs: nothing recomputed
        self.assertEqual(list(LabelSuggestion.objects.filter(
            capture=capture, pool__startswith=proposals.PREFIX).values_list("pk", flat=True)), rows)

    def test_a_proposal_below_the_probability_floor_is_not_shown(self):
        for seed in (95, 96):
            self.review(self.ingested(seed), self.dora, seed)
        capture = self.ingested(seed=94)
        offered = [s for s in self.offered(capture, self.dora) if s["proposed"]]
        doubtful = offered[0]
        LabelSuggestion.objects.filter(
            capture=capture, pool__startswith=proposals.PREFIX, start=doubtful["start"],
            stop=doubtful["stop"]).update(probability=proposals.MIN_PROBABILITY - 0.01)
        again = {(s["start"], s["stop"]): s for s in self.offered(capture, self.dora)}
        shown = again[(doubtful["start"], doubtful["stop"])]
        self.assertFalse(shown["proposed"])
        self.assertIsNone(shown["probability"])
