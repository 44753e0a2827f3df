"""Proposals through a taxonomy change (issue 47): a rename, a retire and a merge each keep
the project's stored frame model valid without a retraining, the detection run's
proposals and an annotator's own follow them, and a model whose proposals fail the
held-out check proposes nothing. Jobs run in-process here."""

from motionlib import labelling, synth
from segmentation import services
from segmentation.models import Adjudication, Label, LabelSuggestion, ProjectCutModel, SegmentLabel
from segmentation.services import taxonomy
from segmentation.services.gold import do_save_gold
from tests.segmentation.test_proposals import ProposalsBase


class TaxonomyTestCase(ProposalsBase):
    def trained(self):
        """bob reviews two takes to the truth (true names), the project trains, and a third
        take is detected with the model."""
        for seed in (92, 93):
            self.review(self.ingested(seed), self.bob, seed)
        self.retrain()
        return self.ingested(seed=94)

    def redetect(self, capture):
        from segmentation import tasks

        run = services.do_redetect(capture, self.alice)
        tasks.detect(run.pk)
        run.refresh_from_db()
        self.assertEqual(run.status, "ready", run.error)
        return run

    def stored_names(self):
        row = ProjectCutModel.objects.get(project=self.project, version=1)
        return set(labelling.FrameModel.from_json(row.labels_model).names) - {""}

    def proposed_ids(self, run):
        return [p["label"] for p in run.proposals]

    def test_a_rename_leaves_the_stored_model_and_every_proposal_as_they_were(self):
        capture = self.trained()
        before, stored = self.proposed_ids(capture.latest_run()), self.stored_names()
        label = Label.objects.get(pk=next(x for x in before if x))
        taxonomy.do_change_label(label, name="renamed action")
        self.assertEqual(self.stored_names(), stored)
        self.assertEqual(self.proposed_ids(self.redetect(capture)), before)
        # bob's own proposals name it by its new name
        self.assertIn("renamed action", self.proposed_labels(capture, self.bob))

    def test_a_retired_label_is_proposed_no_more(self):
        capture = self.trained()
        first = self.proposed_ids(capture.latest_run())
        label = Label.objects.get(pk=next(x for x in first if x))
        self.assertIn(label.name, self.proposed_labels(capture, self.bob))
        taxonomy.do_change_label(label, retired=True)
        self.assertNotIn(label.pk, self.proposed_ids(self.redetect(capture)))
        self.assertNotIn(label.name, self.proposed_labels(capture, self.bob))
        self.assertEqual(ProjectCutModel.objects.filter(project=self.project).count(), 1)

    def test_a_merge_relabels_the_stored_model_and_every_proposal(self):
        capture = self.trained()
        first = self.proposed_ids(capture.latest_run())
        ids = [x for x in dict.fromkeys(first) if x]
        self.assertGreaterEqual(len(ids), 2, first)
        source, target = Label.objects.get(pk=ids[0]), Label.objects.get(pk=ids[1])
        reviewed = SegmentLabel.objects.filter(label=source).count()
        self.assertTrue(reviewed)
        merged = [target.pk if x == source.pk else x for x in first]
        source_id = source.pk
        taxonomy.do_merge_labels(source, target)
        # the stored model knows the source as the target, with no retraining
        self.assertNotIn(str(source_id), self.stored_names())
        self.assertIn(str(target.pk), self.stored_names())
        self.assertEqual(ProjectCutModel.objects.filter(project=self.project).count(), 1)
        # the run's stored proposals, and those of a new detection with that model
        self.assertEqual(self.proposed_ids(capture.latest_finished_run()), merged)
        self.assertEqual(self.proposed_ids(self.redetect(capture)), merged)
        # the reviews' segments, and bob's own proposals
        self.assertFalse(Label.objects.filter(pk=source_id).exists())
        self.assertGreaterEqual(SegmentLabel.objects.filter(label=target).count(), reviewed)
        self.assertNotIn(source.name, self.proposed_labels(capture, self.bob))
        self.assertIn(target.name, self.proposed_labels(capture, self.bob))

    def test_a_merge_moves_gold_labels_too(self):
        capture = self.ingested(seed=92)
        segments = self.review(capture, self.bob, 92)
        names = [a for _, _, a in segments]
        do_save_gold(capture, self.rachel, [s for s, _, _ in segments[1:]], names, 0)
        source = self.project.labels.get(name=names[0])
        source_id = source.pk
        target = self.project.labels.exclude(pk=source_id).filter(name__in=names).first()
        taxonomy.do_merge_labels(source, target)
        gold = Adjudication.objects.get(capture=capture)
        self.assertNotIn(source_id, gold.labels)
        self.assertEqual(gold.labels[0], target.pk)
        self.assertFalse(LabelSuggestion.objects.filter(label_id=source_id).exists())

    def test_only_an_admin_merges_and_a_label_into_itself_is_refused(self):
        walk, punch = self.walk, self.punch
        url = f"/api/projects/{self.project.pk}/labels/{walk.pk}/merge/"
        self.login(self.rachel)
        self.assertEqual(self.client.post(url, {"into": punch.pk}, content_type="application/json").status_code, 403)
        self.login(self.alice)
        response = self.client.post(url, {"into": walk.pk}, content_type="application/json")
        self.assertEqual(response.status_code, 400)
        self.assertIn("itself", response.json()["detail"] if "detail" in response.json() else str(response.json()))
        response = self.client.post(url, {"into": 999999}, content_type="application/json")
        self.assertEqual(response.status_code, 400)
        response = self.client.post(url, {"into": punch.pk}, content_type="application/json")
        self.assertEqual((response.status_code, response.json()["name"]), (200, "punch"))
        self.assertFalse(Label.objects.filter(pk=walk.pk).exists())

    def test_a_model_whose_labels_fail_the_held_out_check_proposes_nothing(self):
        actions = list(synth.ACTIONS)
        for shift, seed in enumerate((92, 93, 95)):
            self.review(self.ingested(seed), self.bob, seed,
                        lambda a, shift=shift: actions[(actions.index(a) + 2 * shift + 1) % len(actions)])
        self.retrain()
        row = ProjectCutModel.objects.get(project=self.project, version=1)
        self.assertEqual(row.labels_model, "")
        capture = self.ingested(seed=94)
        self.assertEqual(capture.latest_run().proposals, [])
        self.assertEqual(self.proposed_labels(capture, self.bob), set())
