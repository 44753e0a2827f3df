"""A submitted review reaches the similar-clip index through a real worker, and this
process, which had the index open, sees the worker's appended update."""

import pytest
from django.contrib.auth import get_user_model

from segmentation import services
from segmentation.models import LibrarySegment
from segmentation.similar import files, index, search
from tests.segmentation.base import synthetic_bvh
from tests.segmentation.integration.conftest import wait_for
from tests.segmentation.integration.test_pipeline import client_for, settled, upload
from tests.segmentation.test_library import submit_review

pytestmark = pytest.mark.integration


@pytest.fixture
def people(transactional_db, settings, shared_media):
    # The workers write the index where this process reads it.
    settings.SIMILAR_INDEX_DIR = shared_media / "similar"
    index.forget()
    users = get_user_model().objects
    alice = users.create_user("alice", password="alice-password")
    bob = users.create_user("bob", password="bob-password")
    project = services.do_create_project(alice, "Studio A")
    services.do_set_member(project, "bob", "annotator")
    services.do_add_label(project, "walk", "#2563eb", "1")
    services.do_add_label(project, "squat", "#dc2626", "2")
    yield project, alice, bob
    index.forget()


def indexed_ids(project):
    """The keys of the project's index as this process sees it (kept open between calls)."""
    opened = index.open_index(project.pk)
    return None if opened is None else set(opened.index.keys().tolist())


def test_it_indexes_the_segments_of_a_submitted_review_on_a_worker(running_workers, people):
    project, alice, bob = people
    ids = [upload(client_for(alice), project, synthetic_bvh(seed=s), name=f"t{s}.bvh") for s in (3, 4)]
    for capture_id in ids:
        wait_for(lambda capture_id=capture_id: settled(capture_id), what="ingest and detection")
    captures = [project.captures.get(pk=pk) for pk in ids]
    submit_review(captures[0], bob, [300, 700], ["walk", "squat", "walk"])
    first = set(LibrarySegment.objects.values_list("id", flat=True))
    assert len(first) == 3
    wait_for(lambda: indexed_ids(project) == first, what="the index of the first review")
    built = files.read_manifest(project.pk)

    # A second take's review: the worker adds its segments to the same index.
    submit_review(captures[1], bob, [400], ["squat", "walk"])
    every = set(LibrarySegment.objects.values_list("id", flat=True))
    wait_for(lambda: indexed_ids(project) == every, what="the index of both reviews")
    appended = files.read_manifest(project.pk)
    assert appended["file"] == built["file"], "the update appended to the same generation"
    assert appended["state"]["delta"] == len(every - first)
    query = LibrarySegment.objects.get(capture=captures[1], start=0)
    visible = LibrarySegment.objects.visible_to(bob).preferred()
    assert index.open_index(project.pk) is not None
    found = [s.pk for s, _ in search.similar(query, visible, k=10)]
    # Every other segment, the query's own span left out.
    assert sorted(found) == sorted(every - {query.pk})
