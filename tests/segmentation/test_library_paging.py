"""Paging the library list without counting every match: exact counts up to a cap, a
capped count beyond it, and pages that still cover every segment once."""

from unittest import mock

from segmentation.api.segments import SegmentPagination
from tests.segmentation.test_library import LibraryTestCase


class PagingTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture, _, _ = self.two_reviews()  # 7 segments
        self.login(self.rachel)

    def get(self, query):
        response = self.client.get(f"/api/segments/{query}")
        assert response.status_code == 200, response.content
        return response.json()

    def test_it_counts_exactly_below_the_cap(self):
        body = self.get("?page_size=2")
        assert (body["count"], body["count_capped"]) == (7, False)

    def test_it_caps_the_count_of_a_larger_match(self):
        with mock.patch.object(SegmentPagination, "count_cap", 3):
            body = self.get("?page_size=2")
        assert (body["count"], body["count_capped"]) == (3, True)
        assert body["next"] and body["previous"] is None

    def test_it_counts_exactly_on_the_last_page_past_the_cap(self):
        with mock.patch.object(SegmentPagination, "count_cap", 3):
            body = self.get("?page_size=2&page=4")
        assert (body["count"], body["count_capped"], body["next"]) == (7, False, None)
        assert len(body["results"]) == 1

    def test_it_counts_past_the_cap_up_to_the_page_asked_for(self):
        with mock.patch.object(SegmentPagination, "count_cap", 2):
            body = self.get("?page_size=2&page=2")
        # Page 2 shows segments 3-4 and there are more: at least 5 exist.
        assert (body["count"], body["count_capped"]) == (5, True)

    def test_it_walks_every_segment_once_through_the_next_links(self):
        with mock.patch.object(SegmentPagination, "count_cap", 3):
            everything = [s["id"] for s in self.get("?page_size=50&ordering=duration")["results"]]
            seen, url, pages = [], "/api/segments/?page_size=2&ordering=duration", 0
            while url:
                body = self.client.get(url).json()
                seen += [s["id"] for s in body["results"]]
                url, pages = body["next"], pages + 1
        assert seen == everything and len(seen) == 7 and pages == 4

    def test_it_links_back_to_the_previous_page(self):
        body = self.get("?page_size=2&page=3")
        assert "page=2" in body["previous"]
        assert "page=" not in self.get("?page_size=2&page=2")["previous"]

    def test_it_answers_404_past_the_last_page(self):
        response = self.client.get("/api/segments/?page_size=2&page=5")
        assert response.status_code == 404
        assert "no page 5" in response.json()["detail"]

    def test_it_refuses_a_page_that_is_not_a_number(self):
        response = self.client.get("/api/segments/?page=last")
        assert response.status_code == 400
        assert "page: must be an integer" in response.json()["detail"]
