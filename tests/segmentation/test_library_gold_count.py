"""An annotator's list counts its gold run from the gold index on SQLite (issue 50): at
100,000 segments, counting the few gold rows in no order read every segment of the
projects (an index of project and superseded) and made an annotator's list slower there
than at a million."""

from unittest import mock

import pytest
from django.db import connection
from django.test.utils import CaptureQueriesContext

from segmentation import services
from segmentation.api.segments import SegmentPagination
from segmentation.models import Label, LibrarySegment
from tests.segmentation.test_library import LibraryTestCase


@pytest.mark.skipif(connection.vendor != "sqlite", reason="SQLite's planner")
class GoldCountTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        capture, _, _ = self.two_reviews()  # bob's 4 segments and dana's 3
        label = Label.objects.filter(project=self.project).first()
        LibrarySegment.objects.bulk_create(
            LibrarySegment(project=self.project, capture=capture, is_gold=True, label=label,
                           start=10 * i, stop=10 * i + 10, duration=1.0) for i in range(5))
        # Bob annotates in several projects: the runs name them as ``project_id IN (...)``.
        for name in ("Studio B", "Studio C"):
            services.do_set_member(services.do_create_project(self.alice, name), "bob", "annotator")
        self.login(self.bob)

    def gold_count(self):
        """The list's page 3 of 2 (the runs before it are counted) and the plan of the
        gold run's count."""
        with mock.patch.object(SegmentPagination, "count_cap", 3), \
                CaptureQueriesContext(connection) as captured:
            body = self.client.get("/api/segments/?page_size=2&page=3").json()
        counts = [q["sql"] for q in captured if "COUNT" in q["sql"] and '"is_gold" IN (1)' in q["sql"]]
        assert counts, "the gold run was not counted"
        with connection.cursor() as cursor:
            cursor.execute("EXPLAIN QUERY PLAN " + counts[0])
            plan = " ".join(str(row[-1]) for row in cursor.fetchall())
        return body, plan

    def test_it_counts_the_gold_run_from_an_index_of_gold_rows(self):
        _, plan = self.gold_count()
        assert "is_gold=?" in plan, plan

    def test_the_page_is_the_same_as_the_list_in_one_page(self):
        body, _ = self.gold_count()
        everything = self.client.get("/api/segments/?page_size=50").json()["results"]
        assert [s["id"] for s in body["results"]] == [s["id"] for s in everything[4:6]]
        assert len(everything) == 9  # bob's 4 and the 5 gold
