"""Capture search on PostgreSQL is served by the trigram index, not a table scan."""

import pytest
from django.contrib.auth import get_user_model
from django.db import connection
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture

pytestmark = pytest.mark.integration


@pytest.fixture
def owner(db, services_env):
    user = get_user_model().objects.create_user("owner")
    project = services.do_create_project(user, "Studio")
    Capture.objects.bulk_create(
        Capture(project=project, name=f"{word}_{i:04d}.bvh", format="bvh", checksum=f"{word}{i}")
        for i in range(2000) for word in ("walk", "squat", "punch")
    )
    with connection.cursor() as cursor:
        cursor.execute("ANALYZE segmentation_capture")
    return user


def test_it_finds_captures_by_a_case_insensitive_substring(owner):
    client = APIClient()
    client.force_authenticate(owner)
    body = client.get("/api/captures/", {"search": "SQUAT_01"}).json()
    assert body["count"] == 100
    assert all("squat_01" in c["name"] for c in body["results"])


def test_it_searches_through_the_trigram_index(owner):
    # At a few thousand rows a scan is as cheap as the index, so the planner may pick
    # either; with other scans priced out, the plan of the bare filter shows whether the
    # SQL Django writes for ``icontains`` matches the index's expression (at 10,000
    # captures it is chosen unprompted: benchmarks/service/capture_list_load.py).
    search = Capture.objects.filter(name__icontains="squat_01").order_by()
    sql, params = search.query.sql_with_params()
    with connection.cursor() as cursor:
        cursor.execute("SET enable_seqscan = off")
        cursor.execute("SET enable_indexscan = off")
        try:
            cursor.execute("EXPLAIN " + sql, params)
            plan = "\n".join(row[0] for row in cursor.fetchall())
        finally:
            cursor.execute("RESET enable_seqscan")
            cursor.execute("RESET enable_indexscan")
    assert "capture_name_trgm" in plan, plan
