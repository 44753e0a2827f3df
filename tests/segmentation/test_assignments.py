from segmentation import services
from segmentation.models import Assignment
from segmentation.services import assignments
from tests.segmentation.base import BaseTestCase


class AssignmentsTestCase(BaseTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        from django.contrib.auth import get_user_model

        cls.dora = get_user_model().objects.create_user("dora", password="dora-password")
        services.do_set_member(cls.project, "dora", "annotator")

    def url(self, suffix=""):
        return f"/api/projects/{self.project.pk}/assignments/{suffix}"

    def assign(self, captures, annotators, per_capture=None):
        body = {"captures": [c.pk for c in captures], "annotators": annotators}
        if per_capture is not None:
            body["per_capture"] = per_capture
        return self.client.post(self.url(), body, format="json")

    def test_it_assigns_many_captures_to_one_annotator(self):
        self.login(self.rachel)
        captures = [self.ready_capture(name=f"c{i}.bvh") for i in range(3)]
        r = self.assign(captures, ["bob"])
        self.assertEqual(r.status_code, 201)
        self.assertEqual(Assignment.objects.filter(annotator=self.bob).count(), 3)

    def test_it_spreads_each_capture_to_n_annotators_evenly(self):
        self.login(self.alice)
        captures = [self.ready_capture(name=f"c{i}.bvh") for i in range(6)]
        r = self.assign(captures, ["bob", "dora", "rachel"], per_capture=2)
        self.assertEqual(r.status_code, 201)
        counts = sorted(Assignment.objects.filter(annotator__username=u).count() for u in ["bob", "dora", "rachel"])
        self.assertEqual(counts, [4, 4, 4])
        for capture in captures:
            self.assertEqual(capture.assignments.count(), 2)

    def test_it_counts_existing_assignments_when_spreading(self):
        self.login(self.alice)
        first = self.ready_capture(name="first.bvh")
        self.assign([first], ["bob"])
        second = self.ready_capture(name="second.bvh")
        self.assign([second], ["bob", "dora"], per_capture=1)
        self.assertEqual(second.assignments.get().annotator, self.dora)

    def test_it_refuses_more_annotators_per_capture_than_given(self):
        self.login(self.alice)
        r = self.assign([self.ready_capture()], ["bob"], per_capture=2)
        self.assertEqual(r.status_code, 400)
        self.assertIn("per_capture", r.json()["detail"])

    def test_it_refuses_a_non_member(self):
        self.login(self.alice)
        r = self.assign([self.ready_capture()], ["charlie"])
        self.assertEqual(r.status_code, 400)
        self.assertIn("charlie", r.json()["detail"])

    def test_annotator_cannot_assign(self):
        self.login(self.bob)
        r = self.assign([self.ready_capture()], ["bob"])
        self.assertEqual(r.status_code, 403)
        self.assertFalse(Assignment.objects.exists())

    def test_it_unassigns_and_keeps_the_review(self):
        capture = self.ready_capture()
        self.login(self.alice)
        assignment_id = self.assign([capture], ["bob"]).json()[0]["id"]
        self.login(self.bob)
        self.client.post(f"/api/captures/{capture.pk}/review/")
        self.login(self.alice)
        self.assertEqual(self.client.delete(self.url(f"{assignment_id}/")).status_code, 204)
        self.assertFalse(Assignment.objects.exists())
        self.assertEqual(capture.reviews.count(), 1)

    def test_it_reassigns_to_another_member(self):
        capture = self.ready_capture()
        self.login(self.alice)
        assignment_id = self.assign([capture], ["bob"]).json()[0]["id"]
        r = self.client.patch(self.url(f"{assignment_id}/"), {"annotator": "dora"}, format="json")
        self.assertEqual((r.status_code, r.json()["annotator"]), (200, "dora"))

    def test_it_refuses_reassigning_to_someone_who_has_the_capture(self):
        capture = self.ready_capture()
        self.login(self.alice)
        rows = self.assign([capture], ["bob", "dora"]).json()
        r = self.client.patch(self.url(f"{rows[0]['id']}/"), {"annotator": "dora"}, format="json")
        self.assertEqual(r.status_code, 400)
        self.assertIn("already assigned", r.json()["detail"])

    def test_it_lists_assignments_with_their_review_state(self):
        capture = self.ready_capture()
        self.login(self.alice)
        self.assign([capture], ["bob"])
        self.login(self.bob)
        self.client.post(f"/api/captures/{capture.pk}/review/")
        self.login(self.rachel)
        rows = self.client.get(self.url()).json()
        self.assertEqual([(r["annotator"], r["state"]) for r in rows], [("bob", "in_progress")])


class UnassignedPickTestCase(BaseTestCase):
    def test_annotator_may_pick_an_unassigned_capture_by_default(self):
        capture = self.ready_capture()
        self.login(self.bob)
        self.assertEqual(self.client.post(f"/api/captures/{capture.pk}/review/").status_code, 200)

    def test_annotator_cannot_start_an_unassigned_capture_when_the_project_forbids_it(self):
        capture = self.ready_capture()
        self.login(self.alice)
        r = self.client.patch(f"/api/projects/{self.project.pk}/", {"annotators_pick_unassigned": False},
                              format="json")
        self.assertEqual(r.status_code, 200)
        self.login(self.bob)
        r = self.client.post(f"/api/captures/{capture.pk}/review/")
        self.assertEqual(r.status_code, 403)
        self.assertIn("not assigned to you", r.json()["detail"])

    def test_an_assigned_annotator_may_start_when_the_project_forbids_picking(self):
        capture = self.ready_capture()
        self.project.annotators_pick_unassigned = False
        self.project.save()
        assignments.do_assign(self.project, self.alice, [capture.pk], ["bob"])
        self.login(self.bob)
        self.assertEqual(self.client.post(f"/api/captures/{capture.pk}/review/").status_code, 200)


class TeamColumnsTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture()
        assignments.do_assign(self.project, self.alice, [self.capture.pk], ["bob", "rachel"])
        self.login(self.bob)
        self.client.post(f"/api/captures/{self.capture.pk}/review/")

    def test_the_capture_list_shows_who_is_assigned_and_each_reviews_state(self):
        self.login(self.alice)
        (row,) = self.client.get("/api/captures/").json()["results"]
        self.assertEqual(row["team"]["assigned"], ["bob", "rachel"])
        self.assertEqual([(r["annotator"], r["status"]) for r in row["team"]["reviews"]],
                         [("bob", "in_progress")])

    def test_the_dashboard_shows_who_is_assigned_and_each_reviews_state(self):
        self.login(self.alice)
        (row,) = self.client.get(f"/api/projects/{self.project.pk}/dashboard/").json()["captures"]
        self.assertEqual(row["assigned"], ["bob", "rachel"])
        self.assertEqual([r["status"] for r in row["review_states"]], ["in_progress"])
