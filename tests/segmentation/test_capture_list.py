from segmentation.models import Capture
from tests.segmentation.base import BaseTestCase


class CaptureListTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.walk_take = self.ready_capture(name="walking.bvh")
        self.punch_take = self.ready_capture(name="punching.bvh", n_frames=500)
        Capture.objects.filter(pk=self.punch_take.pk).update(status="failed", error="bad line 7")
        self.login(self.bob)

    def test_it_lists_the_projects_captures(self):
        body = self.client.get("/api/captures/").json()
        self.assertEqual(body["count"], 2)
        self.assertEqual({c["name"] for c in body["results"]}, {"walking.bvh", "punching.bvh"})

    def test_it_filters_by_status_and_search(self):
        failed = self.client.get("/api/captures/", {"status": "failed"}).json()["results"]
        self.assertEqual([(c["name"], c["error"]) for c in failed], [("punching.bvh", "bad line 7")])
        found = self.client.get("/api/captures/", {"search": "WALK"}).json()["results"]
        self.assertEqual([c["name"] for c in found], ["walking.bvh"])

    def test_it_paginates(self):
        body = self.client.get("/api/captures/", {"page_size": 1}).json()
        self.assertEqual((body["count"], len(body["results"])), (2, 1))
        self.assertIn("page=2", body["next"])

    def test_it_summarises_the_latest_run_in_list_rows(self):
        rows = {c["name"]: c for c in self.client.get("/api/captures/").json()["results"]}
        run = rows["walking.bvh"]["latest_run"]
        self.assertEqual((run["status"], run["n_candidates"]), ("ready", 3))
        self.assertNotIn("candidates", run)
        self.assertNotIn("skeleton", rows["walking.bvh"])

    def test_it_shows_a_capture_with_its_latest_run_and_skeleton(self):
        body = self.client.get(f"/api/captures/{self.walk_take.pk}/").json()
        self.assertEqual(body["duration"], 400 / 120.0)
        self.assertEqual(body["skeleton"]["up"], "y")
        self.assertEqual([c["frame"] for c in body["latest_run"]["candidates"]], [100, 200, 300])
        self.assertIsNone(body["error"])

    def test_it_gives_no_error_as_null_for_captures_and_runs_alike(self):
        detail = self.client.get(f"/api/captures/{self.walk_take.pk}/").json()
        row = next(c for c in self.client.get("/api/captures/").json()["results"]
                   if c["name"] == "walking.bvh")
        errors = [detail["error"], detail["latest_run"]["error"], row["error"],
                  row["latest_run"]["error"]]
        self.assertEqual(errors, [None, None, None, None])

    def test_outsider_sees_nothing(self):
        self.login(self.charlie)
        self.assertEqual(self.client.get("/api/captures/").json()["count"], 0)
        self.assertEqual(self.client.get(f"/api/captures/{self.walk_take.pk}/").status_code, 404)
        r = self.client.get("/api/captures/", {"project": self.project.pk})
        self.assertEqual(r.json()["count"], 0)

    def test_it_refuses_a_non_integer_project_filter(self):
        r = self.client.get("/api/captures/", {"project": "abc"})
        self.assertEqual(r.status_code, 400)
        self.assertIn("project", r.json()["detail"])

    def test_the_list_costs_the_same_queries_for_more_captures(self):
        def queries():
            from django.db import connection
            from django.test.utils import CaptureQueriesContext

            with CaptureQueriesContext(connection) as ctx:
                self.assertEqual(self.client.get("/api/captures/").status_code, 200)
            return len(ctx.captured_queries)

        before = queries()
        for i in range(4):
            self.ready_capture(name=f"more{i}.bvh")
        self.assertEqual(queries(), before)
