"""The clip library API: segments become rows when a review is submitted, the list
filters and sorts them, annotators see their own and gold segments only, and the query
count does not grow with the page."""

import pytest
from django.contrib.auth import get_user_model
from django.db import connection
from django.test.utils import CaptureQueriesContext

from segmentation import services, tasks
from segmentation.models import Capture, LibrarySegment
from segmentation.services import gold
from segmentation.services.library import built_in_request
from tests.segmentation.base import BaseTestCase


def submit_review(capture, user, cuts, labels, worker=True):
    """A review of ``capture`` by ``user`` with exactly ``cuts`` kept and ``labels`` per
    segment (None leaves a segment unlabelled), submitted; with ``worker``, the library
    job a take of points or a long take sends is run here, in-process, as a worker would."""
    review = services.get_or_create_review(capture, user)
    for cut in list(review.cuts.all()):
        if cut.frame not in cuts:
            services.do_change_cut(review, user, cut, review.version, fate="deleted")
    present = set(review.cuts.exclude(fate="deleted").values_list("frame", flat=True))
    for frame in cuts:
        if frame not in present:
            services.do_insert_cut(review, user, frame, review.version)
    for index, name in enumerate(labels):
        if name is not None:
            services.do_label_segment(review, user, index, name, review.version)
    services.do_submit_review(review, user, review.version)
    if worker and not built_in_request(capture):
        tasks.refresh_library(capture.pk)
    return review


class LibraryTestCase(BaseTestCase):
    """Adds dana, a second annotator, and the two reviews worked out by hand in
    tests/segmentation/test_agreement.py (400 frames at 120 fps)."""

    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        get_user_model().objects.create_user("dana", password="dana-password")
        cls.dana = get_user_model().objects.get(username="dana")
        services.do_set_member(cls.project, "dana", "annotator")

    def two_reviews(self, capture=None):
        capture = capture or self.ready_capture()
        bob = submit_review(capture, self.bob, [100, 200, 300], ["walk", "punch", "walk", "punch"])
        dana = submit_review(capture, self.dana, [110, 250], ["walk", "punch", "punch"])
        return capture, bob, dana


class MaterialisationTest(LibraryTestCase):
    def test_it_materialises_labelled_segments_when_a_review_is_submitted(self):
        capture = self.ready_capture()
        review = services.get_or_create_review(capture, self.bob)
        services.do_label_segment(review, self.bob, 0, "walk", review.version)
        assert not LibrarySegment.objects.exists()
        services.do_submit_review(review, self.bob, review.version)
        rows = list(LibrarySegment.objects.order_by("start"))
        # Only the labelled first segment [0, 100) enters the library.
        assert [(s.start, s.stop, s.label.name, s.annotator_id) for s in rows] == [
            (0, 100, "walk", self.bob.pk)]
        assert rows[0].duration == 100 / 120
        assert rows[0].agreement is None  # nobody else reviewed it yet

    def test_it_updates_every_annotators_agreement_when_another_review_comes_in(self):
        capture, _, _ = self.two_reviews()
        bob = {(s.start, s.stop): s.agreement for s in LibrarySegment.objects.filter(annotator=self.bob)}
        # dana labels [0,110) walk, [110,250) punch, [250,400) punch.
        assert bob == {(0, 100): 1.0, (100, 200): 0.9, (200, 300): 0.0, (300, 400): 1.0}


class SegmentListTest(LibraryTestCase):
    def setUp(self):
        super().setUp()
        self.capture, _, _ = self.two_reviews()

    def get(self, query=""):
        response = self.client.get(f"/api/segments/{query}")
        assert response.status_code == 200, response.content
        return response.json()

    def test_it_lists_every_segment_of_the_project_for_a_reviewer(self):
        self.login(self.rachel)
        body = self.get()
        assert body["count"] == 7
        first = body["results"][0]
        assert set(first) >= {"id", "capture", "annotator", "gold", "label", "color", "start",
                              "stop", "fps", "duration", "agreement"}
        assert first["capture"] == {"id": self.capture.pk, "name": "c.bvh"}

    def test_it_shows_an_annotator_only_their_own_segments(self):
        self.login(self.bob)
        body = self.get()
        assert body["count"] == 4
        assert {r["annotator"]["username"] for r in body["results"]} == {"bob"}

    def test_it_shows_an_outsider_nothing(self):
        self.login(self.charlie)
        assert self.get()["count"] == 0
        assert self.get(f"?project={self.project.pk}")["count"] == 0

    def test_it_filters_by_label_annotator_duration_and_agreement(self):
        self.login(self.rachel)
        assert self.get("?label=walk")["count"] == 3
        assert self.get(f"?annotator={self.dana.pk}")["count"] == 3
        # Durations: bob 4 x 100 frames, dana 110, 140, 150 frames at 120 fps.
        assert self.get("?min_duration=1.0")["count"] == 2
        assert self.get("?max_duration=0.9")["count"] == 4
        assert self.get("?min_agreement=0.95")["count"] == 2
        assert self.get(f"?capture={self.capture.pk}&label=punch&annotator={self.bob.pk}")["count"] == 2

    def test_it_filters_by_annotator_username(self):
        self.login(self.rachel)
        assert self.get("?annotator=dana")["count"] == 3
        assert self.get("?annotator=dana")["count"] == self.get(f"?annotator={self.dana.pk}")["count"]
        response = self.client.get("/api/segments/?annotator=nobody")
        assert response.status_code == 400
        assert response.json()["detail"] == "annotator: no user named 'nobody'"

    def test_it_sorts_by_duration_and_agreement(self):
        self.login(self.rachel)
        durations = [r["duration"] for r in self.get("?ordering=-duration")["results"]]
        assert durations == sorted(durations, reverse=True)
        agreements = [r["agreement"] for r in self.get("?ordering=agreement")["results"]]
        assert agreements == sorted(agreements)

    def test_it_rejects_bad_filters_naming_them(self):
        self.login(self.rachel)
        for query, message in [
            ("?min_duration=abc", "min_duration: must be a number, got 'abc'"),
            ("?min_agreement=2", "min_agreement: must be between 0 and 1, got 2"),
            ("?gold=maybe", "gold: must be true or false, got 'maybe'"),
            ("?ordering=colour", "ordering: must be one of"),
            ("?project=x", "project: must be an integer, got 'x'"),
        ]:
            response = self.client.get(f"/api/segments/{query}")
            assert response.status_code == 400, query
            assert message in response.json()["detail"]

    def test_it_pages_results(self):
        self.login(self.rachel)
        body = self.get("?page_size=3&ordering=capture")
        assert len(body["results"]) == 3 and body["next"]
        assert [r["start"] for r in body["results"]] == [0, 0, 100]

    def test_it_answers_with_a_fixed_number_of_queries_whatever_the_page_size(self):
        self.login(self.rachel)
        counts = []
        for size in (1, 7):
            with CaptureQueriesContext(connection) as queries:
                self.get(f"?page_size={size}")
            counts.append(len(queries))
        # Memberships, the page's ids, its rows (with capture, annotator and label
        # joined), their attribute values, and a count unless the page is the last one.
        assert counts == [5, 4]

    def test_it_requires_login(self):
        assert self.client.get("/api/segments/").status_code in (401, 403)

    def test_it_lists_each_segment_field_for_field_as_its_detail_shows_it(self):
        # The list builds its rows from columns, the detail through SegmentSerializer.
        # Gold rows have no annotator; a take of points has other export formats, and with
        # one review its segments no agreement.
        gold.do_save_gold(self.capture, self.rachel, [100, 200, 300],
                          ["walk", "punch", "walk", "punch"], 0)
        points = self.ready_capture(name="p.c3d")
        submit_review(points, self.bob, [200], ["walk", "punch"])
        Capture.objects.filter(pk=points.pk).update(format="c3d")
        self.login(self.rachel)
        rows = self.get("?gold=true")["results"] + self.get("?gold=false")["results"]
        assert {r["annotator"] is None for r in rows} == {True, False}
        assert {r["agreement"] is None for r in rows} == {True, False}
        assert {tuple(r["export_formats"]) for r in rows} == {("bvh", "fbx", "glb"), ("c3d", "csv")}
        for row in rows:
            detail = self.client.get(f"/api/segments/{row['id']}/").json()
            assert list(row.items()) == list(detail.items())


class SegmentDetailTest(LibraryTestCase):
    def test_it_shows_a_segment_to_its_annotator_and_hides_it_from_others(self):
        self.two_reviews()
        danas = LibrarySegment.objects.filter(annotator=self.dana).first()
        self.login(self.dana)
        assert self.client.get(f"/api/segments/{danas.pk}/").json()["label"] == danas.label.name
        self.login(self.bob)
        assert self.client.get(f"/api/segments/{danas.pk}/").status_code == 404
        self.login(self.charlie)
        assert self.client.get(f"/api/segments/{danas.pk}/").status_code == 404


class UnreadableTakeTest(LibraryTestCase):
    """``ready_capture`` stores a file that is not a valid BVH and a skeleton with no
    recognisable body parts: the library must say so rather than fail."""

    def setUp(self):
        super().setUp()
        self.capture, _, _ = self.two_reviews()
        self.segment = LibrarySegment.objects.filter(annotator=self.bob).first()
        self.login(self.rachel)

    def test_it_explains_why_a_segment_cannot_be_exported(self):
        response = self.client.get(f"/api/segments/{self.segment.pk}/export.bvh")
        assert response.status_code == 400
        assert response.json()["detail"].startswith("c.bvh")

    def test_it_lists_unreadable_takes_in_the_zip_instead_of_breaking_it(self):
        import io
        import zipfile

        response = self.client.get("/api/segments/export.zip")
        archive = zipfile.ZipFile(io.BytesIO(b"".join(response.streaming_content)))
        assert sorted(archive.namelist()) == ["errors.txt", "manifest.csv", "manifest.json"]
        assert archive.read("errors.txt").decode().startswith(f"capture {self.capture.pk} (c.bvh): c.bvh")

    def test_it_explains_why_a_segment_has_no_similar_clips(self):
        response = self.client.get(f"/api/segments/{self.segment.pk}/similar/")
        assert response.status_code == 400
        assert "could not be mapped to body parts" in response.json()["detail"]

    def test_it_refuses_an_export_of_more_than_the_limit(self):
        from segmentation.files import exports

        saved, exports.MAX_EXPORT_SEGMENTS = exports.MAX_EXPORT_SEGMENTS, 3
        try:
            response = self.client.get("/api/segments/export.zip")
        finally:
            exports.MAX_EXPORT_SEGMENTS = saved
        assert response.status_code == 400
        assert response.json()["detail"].startswith("export: the query matches 7 segments")


@pytest.mark.integration
class PostgresSegmentListTest(LibraryTestCase):
    """The same query count on PostgreSQL, where the library lives in production
    (``make pytest`` runs the integration tests there)."""

    def test_it_answers_with_five_queries_on_postgresql(self):
        if connection.vendor != "postgresql":
            pytest.skip("needs PostgreSQL: DATABASE_URL=postgres://… (make pytest sets it)")
        self.two_reviews()
        self.login(self.rachel)
        for size in (1, 7):
            with CaptureQueriesContext(connection) as queries:
                response = self.client.get(f"/api/segments/?page_size={size}&label=walk&min_agreement=0")
            assert response.status_code == 200
            assert response.json()["count"] == 3
            # Memberships, the label's ids, the page's ids, its rows, their attribute
            # values; and the count when the page is not the last.
            assert len(queries) == (6 if size < 3 else 5)


class LostPositionsTest(LibraryTestCase):
    def test_it_still_submits_a_review_when_the_positions_file_is_gone(self):
        from pathlib import Path

        from motionlib import synth

        capture = self.ready_capture()
        # A skeleton that maps to body parts, so the library does try to read positions.
        take, _ = synth.generate(seed=0, fps=120.0, duration=2.0)
        capture.skeleton = {**capture.skeleton, "joints": list(take.skeleton.names)}
        capture.save()
        Path(capture.positions.path).unlink()
        submit_review(capture, self.bob, [100], ["walk", "punch"])
        rows = LibrarySegment.objects.order_by("start")
        assert [(r.label.name, r.descriptor) for r in rows] == [("walk", None), ("punch", None)]
