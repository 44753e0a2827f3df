"""Migration 0019 adds what the gate keeps on each training, and records which captures
the models trained before it learnt from: those with a submitted review or a gold version
when the training started."""

import datetime

from tests.segmentation.migrations import MigrationTestCase

BEFORE = [("segmentation", "0018_username_keys")]
AFTER = [("segmentation", "0019_cut_model_gate")]
T0 = datetime.datetime(2026, 12, 1, 12, 0, tzinfo=datetime.UTC)


def at(minutes):
    return T0 + datetime.timedelta(minutes=minutes)


class CutModelGateMigrationTest(MigrationTestCase):
    def setUp(self):
        apps = self.migrate(BEFORE)
        model = lambda name: apps.get_model("segmentation", name)  # noqa: E731
        user = apps.get_model("auth", "User").objects.create(username="bob")
        project = model("Project").objects.create(name="Studio")
        other = model("Project").objects.create(name="Other")

        def capture(name, project=project):
            return model("Capture").objects.create(project=project, name=name, checksum=name,
                                                   format="bvh", fps=120.0, n_frames=400,
                                                   status="ready")

        early, late, adjudicated, elsewhere = (capture("early"), capture("late"), capture("gold"),
                                               capture("elsewhere", other))
        review = model("Review").objects
        review.create(capture=early, annotator=user, status="submitted", submitted_at=at(1))
        review.create(capture=late, annotator=user, status="submitted", submitted_at=at(20))
        review.create(capture=elsewhere, annotator=user, status="submitted", submitted_at=at(1))
        model("Adjudication").objects.create(capture=adjudicated, adjudicator=user, cuts=[100],
                                             created_at=at(2))
        cut_models = model("ProjectCutModel").objects
        self.v1 = cut_models.create(project=project, status="ready", version=1, model="{}",
                                    n_takes=2, claimed_at=at(10), finished_at=at(11))
        self.failed = cut_models.create(project=project, status="failed", error="x", claimed_at=at(30))
        self.ids = {"early": early.pk, "gold": adjudicated.pk}
        self.apps = self.migrate(AFTER)

    def test_a_trained_model_learnt_from_the_takes_reviewed_before_its_training_started(self):
        row = self.apps.get_model("segmentation", "ProjectCutModel").objects.get(pk=self.v1.pk)
        self.assertEqual(row.trained_on, sorted([self.ids["early"], self.ids["gold"]]))
        self.assertEqual((row.refused, row.held_out_takes, row.held_out_f1), ("", None, None))

    def test_a_failed_training_learnt_from_nothing(self):
        row = self.apps.get_model("segmentation", "ProjectCutModel").objects.get(pk=self.failed.pk)
        self.assertEqual(row.trained_on, [])
