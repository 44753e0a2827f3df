"""Statements: a queryset compiled once per shape reads, with new values, what the queryset
itself reads, and one whose SQL would depend on a value is refused when it is compiled."""

from unittest import mock

import pytest
from django.db import connection

from segmentation.db.statements import Statement
from segmentation.models import LibrarySegment
from tests.segmentation.base import BaseTestCase


def segments(key, project_id, start):
    """The statement's queryset: ``key`` says whether gold rows only are read."""
    found = LibrarySegment.objects.filter(project_id=project_id, start__gte=start)
    if key == "gold":
        found = found.filter(is_gold__in=[True])
    return found.order_by("id").values_list("id", "is_gold", "capture__skeleton", "start", "agreement")


class StatementTest(BaseTestCase):
    def setUp(self):
        super().setUp()
        capture = self.ready_capture(name="a.bvh", n_frames=2000)
        self.rows = LibrarySegment.objects.bulk_create(
            LibrarySegment(project=self.project, capture=capture, label=self.walk, start=start,
                           stop=start + 50, duration=50 / 120, is_gold=start % 200 == 0,
                           annotator=None if start % 200 == 0 else self.bob,
                           agreement=None if start == 100 else 0.5)
            for start in range(0, 1000, 100))

    def test_it_reads_what_the_queryset_reads(self):
        statement = Statement(segments)
        for key in ("all", "gold"):
            for project_id, start in ((self.project.pk, 0), (self.project.pk, 450),
                                      (self.other_project.pk, 0), (self.project.pk, 5000)):
                expected = list(segments(key, project_id, start))
                found = statement.rows("default", key, project_id=project_id, start=start)
                assert found == expected, (key, project_id, start)
        # The columns come as the queryset gives them: booleans, parsed JSON, None.
        row = statement.rows("default", "all", project_id=self.project.pk, start=0)[1]
        assert row[1] is False and isinstance(row[2], dict) and row[4] is None

    def test_it_compiles_each_shape_once(self):
        built = mock.Mock(side_effect=segments)
        statement = Statement(built)
        for start in (0, 300, 600):
            statement.rows("default", "all", project_id=self.project.pk, start=start)
        assert built.call_count == 2  # twice, with two sets of stand-ins
        statement.rows("default", "gold", project_id=self.project.pk, start=0)
        assert built.call_count == 4

    def test_it_refuses_sql_that_changes_with_a_value(self):
        def inlined(key, project_id, start):
            return (LibrarySegment.objects.filter(project_id=project_id)
                    .extra(where=[f"start >= {start}"]).values_list("id"))

        with pytest.raises(TypeError, match="changes with its values"):
            Statement(inlined).rows("default", None, project_id=self.project.pk, start=0)

    def test_it_refuses_a_value_it_does_not_pass_on(self):
        def ignores(key, project_id, start):
            return LibrarySegment.objects.filter(project_id=project_id).values_list("id")

        with pytest.raises(TypeError, match=r"does not use \['start'\]"):
            Statement(ignores).rows("default", None, project_id=self.project.pk, start=0)


    def test_floats_strings_and_tuples_are_values_and_a_window_or_count_reads_part(self):
        def built(key, ids, longest, name):
            return (LibrarySegment.objects.filter(pk__in=ids, duration__lte=longest, label__name=name)
                    .order_by("-id").values_list("id", flat=True))

        statement = Statement(built)
        ids = tuple(row.pk for row in self.rows)
        for chosen, longest, name in ((ids[:3], 1.0, "walk"), (ids[2:5], 1.0, "walk"),
                                      (ids[:3], 0.1, "walk"), (ids, 1.0, "run"), (ids, 1.0, "walk")):
            expected = list(built(None, chosen, longest, name))
            found = [pk for pk, in statement.rows("default", None, ids=chosen, longest=longest, name=name)]
            assert found == expected, (chosen, longest, name)
        window = statement.rows("default", None, window=(2, 3), ids=ids, longest=1.0, name="walk")
        assert [pk for pk, in window] == list(built(None, ids, 1.0, "walk")[2:5])
        assert statement.count("default", None, 4, ids=ids, longest=1.0, name="walk") == 4
        assert statement.count("default", None, 100, ids=ids[:6], longest=1.0, name="walk") == 6

    def test_a_partial_statement_may_leave_values_unused(self):
        def one_of(key, project_id, start):
            found = LibrarySegment.objects.filter(project_id=project_id)
            return (found if key == "project" else found.filter(start__gte=start)).values_list("id")

        with pytest.raises(TypeError, match=r"does not use \['start'\]"):
            Statement(one_of).rows("default", "project", project_id=self.project.pk, start=0)
        partial = Statement(one_of, partial=True)
        assert len(partial.rows("default", "project", project_id=self.project.pk, start=500)) == 10
        assert len(partial.rows("default", "start", project_id=self.project.pk, start=500)) == 5


@pytest.mark.integration
class PostgresStatementTest(StatementTest):
    """The same on PostgreSQL, where Django passes some integers typed and JSON as text."""

    def setUp(self):
        if connection.vendor != "postgresql":
            pytest.skip("needs PostgreSQL: DATABASE_URL=postgres://… (make pytest sets it)")
        super().setUp()
