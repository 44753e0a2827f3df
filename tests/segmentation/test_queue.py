from segmentation.services import assignments
from tests.segmentation.base import BaseTestCase


class QueueTestCase(BaseTestCase):
    def queue(self, **params):
        return self.client.get("/api/queue/", params)

    def test_it_lists_assigned_captures_oldest_first_with_duration_and_candidates(self):
        older = self.ready_capture(name="older.bvh", candidates=(10, 20))
        newer = self.ready_capture(name="newer.bvh", candidates=(10, 20, 30))
        assignments.do_assign(self.project, self.alice, [older.pk], ["bob"])
        assignments.do_assign(self.project, self.alice, [newer.pk], ["bob"])
        self.login(self.bob)
        items = self.queue().json()
        self.assertEqual([i["capture"]["name"] for i in items], ["older.bvh", "newer.bvh"])
        self.assertEqual([i["capture"]["n_candidates"] for i in items], [2, 3])
        self.assertAlmostEqual(items[0]["capture"]["duration"], 400 / 120)
        self.assertEqual({i["state"] for i in items}, {"assigned"})

    def test_it_shows_in_progress_and_submitted_states(self):
        started = self.ready_capture(name="started.bvh")
        done = self.ready_capture(name="done.bvh")
        assignments.do_assign(self.project, self.alice, [started.pk, done.pk], ["bob"])
        self.login(self.bob)
        self.client.post(f"/api/captures/{started.pk}/review/")
        self.client.post(f"/api/captures/{done.pk}/review/")
        self.client.post(f"/api/captures/{done.pk}/review/submit/", {"version": 1}, format="json")
        states = {i["capture"]["name"]: i["state"] for i in self.queue().json()}
        self.assertEqual(states, {"started.bvh": "in_progress", "done.bvh": "submitted"})

    def test_it_includes_unassigned_captures_the_annotator_picked(self):
        picked = self.ready_capture(name="picked.bvh")
        self.login(self.bob)
        self.client.post(f"/api/captures/{picked.pk}/review/")
        (item,) = self.queue().json()
        self.assertEqual((item["capture"]["name"], item["assigned"]), ("picked.bvh", False))

    def test_annotator_cannot_see_another_members_queue(self):
        capture = self.ready_capture()
        assignments.do_assign(self.project, self.alice, [capture.pk], ["rachel"])
        self.login(self.bob)
        r = self.queue(project=self.project.pk, user="rachel")
        self.assertEqual(r.status_code, 403)

    def test_reviewer_sees_an_annotators_queue(self):
        capture = self.ready_capture()
        assignments.do_assign(self.project, self.alice, [capture.pk], ["bob"])
        self.login(self.rachel)
        r = self.queue(project=self.project.pk, user="bob")
        self.assertEqual([i["capture"]["id"] for i in r.json()], [capture.pk])

    def test_it_leaves_out_projects_the_caller_has_left(self):
        capture = self.ready_capture()
        assignments.do_assign(self.project, self.alice, [capture.pk], ["bob"])
        self.project.memberships.filter(user=self.bob).delete()
        self.login(self.bob)
        self.assertEqual(self.queue().json(), [])
