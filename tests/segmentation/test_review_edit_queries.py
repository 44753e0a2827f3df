"""What an edit of a review costs the database, and what its answer carries: a cut move
is the review page's most frequent request (a drag sends one per release)."""

from django.db import connection
from django.test.utils import CaptureQueriesContext

from tests.segmentation.base import BaseTestCase

MAX_QUERIES_PER_MOVE = 12


class CutMoveTestCase(BaseTestCase):
    def setUp(self):
        super().setUp()
        self.capture = self.ready_capture(candidates=(100, 200, 300))
        self.login(self.bob)
        self.review = self.client.post(f"/api/captures/{self.capture.pk}/review/").json()
        self.cut = self.review["cuts"][1]

    def move(self, frame, version):
        return self.client.patch(
            f"/api/captures/{self.capture.pk}/review/cuts/{self.cut['id']}/",
            {"frame": frame, "version": version}, format="json",
        )

    def test_it_moves_a_cut_in_at_most_twelve_queries(self):
        with CaptureQueriesContext(connection) as queries:
            r = self.move(210, self.review["version"])
        self.assertEqual(r.status_code, 200, r.content)
        self.assertEqual([c["frame"] for c in r.json()["cuts"]], [100, 210, 300])
        sql = "\n".join(q["sql"] for q in queries.captured_queries)
        self.assertLessEqual(len(queries), MAX_QUERIES_PER_MOVE, sql)

    def test_the_answer_of_an_edit_carries_no_adaptation_summary(self):
        r = self.move(210, self.review["version"])
        self.assertNotIn("adaptation", r.json())

    def test_the_review_page_reads_the_adaptation_summary_from_the_review(self):
        self.move(210, self.review["version"])
        page = self.client.get(f"/api/captures/{self.capture.pk}/review/").json()
        self.assertEqual(page["adaptation"]["project_model"], None)
        self.assertEqual(page["adaptation"]["model_version"], None)
