"""POST /api/captures/{id}/redetect/: reviewers and admins detect again with the
project's method and newest model, on captures nobody has started reviewing."""

from segmentation.models import DetectionRun, ProjectCutModel
from tests.segmentation.base import BaseTestCase


class RedetectTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        self.url = f"/api/captures/{self.capture.pk}/redetect/"

    def redetect(self, user):
        self.login(user)
        with self.captureOnCommitCallbacks() as callbacks:
            response = self.client.post(self.url)
        return response, callbacks

    def test_a_reviewer_queues_a_new_detection_with_the_project_defaults(self):
        response, callbacks = self.redetect(self.rachel)
        self.assertEqual(response.status_code, 202, response.content)
        run = DetectionRun.objects.get(pk=response.json()["id"])
        self.assertEqual((run.status, run.method, run.created_by), ("queued", "default", self.rachel))
        self.assertEqual(len(callbacks), 1)

    def test_an_admin_can_too(self):
        response, _ = self.redetect(self.alice)
        self.assertEqual(response.status_code, 202, response.content)

    def test_an_annotator_is_refused(self):
        response, callbacks = self.redetect(self.bob)
        self.assertEqual(response.status_code, 403)
        self.assertIn("reviewers and admins", response.json()["detail"])
        self.assertEqual(self.capture.runs.count(), 1)
        self.assertEqual(callbacks, [])

    def test_an_outsider_gets_404(self):
        response, _ = self.redetect(self.charlie)
        self.assertEqual(response.status_code, 404)

    def test_it_refuses_a_capture_someone_started_reviewing(self):
        self.login(self.bob)
        self.client.post(f"/api/captures/{self.capture.pk}/review/")
        response, callbacks = self.redetect(self.rachel)
        self.assertEqual(response.status_code, 400)
        self.assertIn("bob started reviewing", response.json()["detail"])
        self.assertEqual(self.capture.runs.count(), 1)
        self.assertEqual(callbacks, [])

    def test_it_refuses_while_a_detection_is_pending(self):
        self.redetect(self.rachel)
        response, _ = self.redetect(self.rachel)
        self.assertEqual(response.status_code, 400)
        self.assertIn("already has a detection queued", response.json()["detail"])

    def test_it_refuses_a_capture_that_is_not_ready(self):
        self.capture.status = "failed"
        self.capture.save(update_fields=["status"])
        response, _ = self.redetect(self.rachel)
        self.assertEqual(response.status_code, 400)
        self.assertIn("detection needs a ready capture", response.json()["detail"])


class CaptureListReviewStartedTestCase(BaseTestCase):
    def test_it_says_which_captures_someone_started_reviewing(self):
        opened, untouched = self.ready_capture(name="a.bvh"), self.ready_capture(name="b.bvh")
        self.login(self.bob)
        self.client.post(f"/api/captures/{opened.pk}/review/")
        rows = {c["id"]: c for c in self.client.get("/api/captures/").json()["results"]}
        self.assertEqual(
            (rows[opened.pk]["review_started"], rows[untouched.pk]["review_started"]), (True, False)
        )


class ReviewAdaptationTestCase(BaseTestCase):
    """The review's ``adaptation``: where its candidates came from."""

    def adaptation(self, capture):
        self.login(self.bob)
        return self.client.get(f"/api/captures/{capture.pk}/review/").json()["adaptation"]

    def test_zero_shot_candidates_are_not_adapted(self):
        adapted = self.adaptation(self.ready_capture())
        self.assertEqual(
            adapted,
            {"model_version": None, "n_takes": None, "held_out": None, "project_model": None,
             "training": False, "training_error": None, "training_refused": None,
             "training_skipped": None},
        )

    def test_it_names_the_model_and_the_reviewed_takes_it_learnt_from(self):
        capture = self.ready_capture()
        capture.runs.update(model_version=3, model_n_takes=12)
        ProjectCutModel.objects.create(project=self.project, status="ready", version=3,
                                       model="{}", n_takes=12, n_cuts=40)
        adapted = self.adaptation(capture)
        self.assertEqual((adapted["model_version"], adapted["n_takes"]), (3, 12))
        self.assertEqual(adapted["project_model"],
                         {"version": 3, "n_takes": 12, "n_cuts": 40, "held_out": None})

    def test_it_says_when_a_training_is_under_way(self):
        ProjectCutModel.objects.create(project=self.project)
        self.assertTrue(self.adaptation(self.ready_capture())["training"])
