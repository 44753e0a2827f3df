"""The library list's pages, under every filter and order, hold exactly the segments of the
obvious query (the visible segments filtered and sorted by the database, labels and
annotators joined by name) in its order: walking the next links, and jumping to page 100.
Ordering by label reads one label name at a time; it follows renames at once and merges a
name that several projects share."""

import itertools
from unittest import mock

import numpy as np
import pytest
from django.db import connection

from segmentation import services
from segmentation.models import Capture, LibrarySegment
from segmentation.queries import library
from segmentation.queries.library import ORDERINGS
from segmentation.services.taxonomy import do_change_label
from tests.segmentation.test_library import LibraryTestCase

FILTERS = [
    "", "project={a}", "project={b}", "label=walk", "project={a}&label=walk", "label=kick",
    "label=nothing", "annotator=bob", "annotator={dana}", "gold=true", "gold=false",
    "capture={capture}", "min_duration=1&max_duration=3", "project={a}&label=punch&min_duration=2",
    "min_agreement=0.5",
]


def oracle(user, query):
    """Ids of the list for ``query`` by the obvious query: joins and one ORDER BY."""
    params = dict(p.split("=", 1) for p in query.split("&") if p)
    rows = LibrarySegment.objects.visible_to(user)
    gold = params.pop("gold", None)
    rows = rows.filter(superseded=False) if gold is None else rows.filter(is_gold=gold == "true")
    lookups = {"project": "project_id", "capture": "capture_id", "label": "label__name",
               "min_duration": "duration__gte", "max_duration": "duration__lte",
               "min_agreement": "agreement__gte"}
    for name, value in params.items():
        if name == "annotator":
            key = "annotator_id" if value.isdigit() else "annotator__username"
            rows = rows.filter(**{key: value})
        elif name != "ordering":
            rows = rows.filter(**{lookups[name]: value})
    return list(rows.order_by(*ORDERINGS[params.get("ordering", "recent")])
                .values_list("id", flat=True))


class ListPagesTest(LibraryTestCase):
    @classmethod
    def setUpTestData(cls):
        super().setUpTestData()
        services.do_set_member(cls.other_project, "rachel", "reviewer")
        services.do_set_member(cls.other_project, "bob", "annotator")
        services.do_set_member(cls.other_project, "dana", "annotator")
        services.do_add_label(cls.other_project, "walk", "#111111", "1")
        services.do_add_label(cls.other_project, "kick", "#222222", "2")
        cls.a, cls.b = cls.project, cls.other_project
        cls.make_library(np.random.default_rng(35), 260)

    @classmethod
    def make_library(cls, rng, n):
        """``n`` segments over both projects: two annotators and gold, superseded rows,
        durations and agreements with ties and nulls."""
        captures = {p.pk: [Capture.objects.create(
            project=p, name=f"{p.pk}-{i}.bvh", format="bvh", checksum=f"{p.pk}-{i}",
            status="ready", fps=120.0, n_frames=10_000, original=f"{p.pk}-{i}.bvh")
            for i in range(3)] for p in (cls.a, cls.b)}
        labels = {p.pk: list(p.labels.all()) for p in (cls.a, cls.b)}
        rows = []
        for _ in range(n):
            project = cls.a if rng.random() < 0.6 else cls.b
            gold = rng.random() < 0.2
            start = int(rng.integers(0, 9_000))
            length = int(rng.choice([120, 240, 300, 360, 480]))
            rows.append(LibrarySegment(
                project=project, capture=rng.choice(captures[project.pk]),
                annotator=None if gold else (cls.bob if rng.random() < 0.5 else cls.dana),
                is_gold=gold, superseded=not gold and rng.random() < 0.15,
                label=rng.choice(labels[project.pk]), start=start, stop=start + length,
                duration=length / 120.0,
                agreement=None if rng.random() < 0.2 else float(rng.choice([0.25, 0.5, 0.75, 1.0]))))
        LibrarySegment.objects.bulk_create(rows)
        cls.capture = captures[cls.a.pk][0]

    def query(self, template, ordering):
        query = template.format(a=self.a.pk, b=self.b.pk, dana=self.dana.pk, capture=self.capture.pk)
        return "&".join(p for p in (query, f"ordering={ordering}") if p)

    def pages(self, query, page_size):
        seen, url = [], f"/api/segments/?{query}&page_size={page_size}"
        while url:
            response = self.client.get(url)
            assert response.status_code == 200, response.content
            seen += [s["id"] for s in response.json()["results"]]
            url = response.json()["next"]
        return seen

    def test_every_filter_and_order_pages_through_exactly_the_obvious_querys_segments(self):
        for user in (self.rachel, self.bob):
            self.login(user)
            for template in FILTERS:
                for ordering in ORDERINGS:
                    query = self.query(template, ordering)
                    with self.subTest(user=user.username, query=query):
                        assert self.pages(query, 25) == oracle(user, query)

    def test_the_hundredth_page_is_the_hundredth_slice_of_every_order(self):
        self.login(self.rachel)
        for ordering in ORDERINGS:
            for template in ("", "project={a}", "label=walk"):
                query = self.query(template, ordering)
                expected = oracle(self.rachel, query)
                assert len(expected) >= 100
                with self.subTest(query=query):
                    body = self.client.get(f"/api/segments/?{query}&page_size=1&page=100").json()
                    assert [s["id"] for s in body["results"]] == expected[99:100]
                    assert body["count"] == len(expected) and not body["count_capped"]
                    assert (body["next"] is not None) == (len(expected) > 100)

    def test_newest_first_an_annotator_and_a_member_of_both_kinds_see_the_obvious_pages(self):
        # Read as a union of runs (everything of the projects one reviews; one's own and the
        # gold segments of those one annotates): each segment once, counted once.
        # Beyond MAX_MERGED_RUNS runs, the runs of each label are merged here, not by the
        # database.
        services.do_set_member(self.b, "dana", "reviewer")
        for user, most in itertools.product((self.rachel, self.bob, self.dana), (100, 1)):
            self.login(user)
            for template in FILTERS:
                query = self.query(template, "recent")
                expected = oracle(user, query)
                with self.subTest(user=user.username, query=query, most=most), \
                        mock.patch.object(library, "MAX_MERGED_RUNS", most):
                    assert self.pages(query, 7) == expected
                    body = self.client.get(f"/api/segments/?{query}&page_size=7").json()
                    assert body["count"] == len(expected)

    def test_by_label_it_follows_a_renamed_label_at_once(self):
        self.login(self.rachel)
        query = self.query("project={a}", "label")
        before = self.pages(query, 50)
        do_change_label(self.walk, name="a walk")
        after = self.pages(query, 50)
        assert after == oracle(self.rachel, query) and after != before
        first = LibrarySegment.objects.get(pk=after[0])
        assert first.label.name == "a walk"

    def test_by_label_one_name_of_several_projects_is_one_run_by_id(self):
        self.login(self.rachel)
        ids = self.pages(self.query("", "label"), 50)
        walks = [pk for pk in ids if LibrarySegment.objects.get(pk=pk).label.name == "walk"]
        assert {LibrarySegment.objects.get(pk=pk).project_id for pk in walks} == {self.a.pk, self.b.pk}
        assert walks == sorted(walks)
        first, last = ids.index(walks[0]), ids.index(walks[-1])
        assert ids[first:last + 1] == walks

    def test_a_label_no_visible_project_has_matches_nothing(self):
        self.login(self.bob)
        body = self.client.get(f"/api/segments/?project={self.a.pk}&label=kick").json()
        assert (body["count"], body["results"], body["next"]) == (0, [], None)

    def test_a_query_of_a_shape_seen_before_is_run_with_its_values_not_built_again(self):
        self.login(self.bob)
        with mock.patch.object(library, "ordered_parts", wraps=library.ordered_parts) as built:
            for label, low in (("walk", 1), ("punch", 2), ("walk", 3), ("punch", 1)):
                query = self.query(f"label={label}&min_duration={low}", "recent")
                assert self.pages(query, 5) == oracle(self.bob, query)
                if label == "punch" and low == 2:
                    seen = built.call_count
        assert built.call_count == seen

    def test_on_sqlite_the_list_has_its_covering_indexes(self):
        if connection.vendor != "sqlite":
            self.skipTest("SQLite only: PostgreSQL's list indexes INCLUDE the filtered columns")
        from importlib import import_module

        wanted = {**import_module("segmentation.migrations.0020_library_list_sqlite_indexes").INDEXES,
                  **import_module("segmentation.migrations.0021_library_list_sqlite_seek_indexes").INDEXES}
        with connection.cursor() as cursor:
            cursor.execute("SELECT name FROM sqlite_master WHERE type = 'index' "
                           "AND tbl_name = 'segmentation_librarysegment'")
            present = {row[0] for row in cursor.fetchall()}
        assert set(wanted) <= present


@pytest.mark.integration
class PostgresListPagesTest(ListPagesTest):
    """The same pages on PostgreSQL, which reads an annotator's runs as one OR, or, with a
    label filter, as one run per label and visible run (``0022``)."""

    def setUp(self):
        if connection.vendor != "postgresql":
            pytest.skip("needs PostgreSQL: DATABASE_URL=postgres://… (make pytest sets it)")
        super().setUp()

    def test_on_postgresql_an_annotators_label_runs_have_their_indexes(self):
        from importlib import import_module

        wanted = import_module("segmentation.migrations.0022_library_list_postgres_label_runs").INDEXES
        with connection.cursor() as cursor:
            cursor.execute("SELECT indexname FROM pg_indexes WHERE tablename = 'segmentation_librarysegment'")
            present = {row[0] for row in cursor.fetchall()}
        assert set(wanted) <= present
