"""Assignments, My queue, submit-and-next, and returning a review, driven in Chromium with
the real roles: a reviewer assigns from the capture list, the annotator works through
the queue, the reviewer returns a review with a comment, the annotator resubmits.
An annotator cannot assign, return, or see another member's queue."""

import pytest
from playwright.sync_api import expect

from tests.e2e.conftest import synthetic_bvh


@pytest.fixture
def takes(studio):
    """Three short synthetic takes, ingested and detected in-process, oldest first."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services, tasks
    from segmentation.models import Capture, DetectionRun

    captures = []
    for seed in (11, 12, 13):
        upload = SimpleUploadedFile(f"take_{seed}.bvh", synthetic_bvh(seed=seed, duration=12.0))
        capture, _ = services.do_upload_capture(studio["project"], studio["alice"], upload)
        tasks.ingest(capture.pk)
        for run in DetectionRun.objects.filter(capture=capture, status="queued"):
            tasks.detect(run.pk)
        captures.append(Capture.objects.get(pk=capture.pk))
    assert all(c.status == "ready" for c in captures)
    return captures


def fetch(page, method, url, body=None):
    """A request from inside the page, with its session and CSRF token: what the UI could send."""
    return page.evaluate(
        """async ([method, url, body]) => {
            const token = document.cookie.split('; ').find(c => c.startsWith('csrftoken='))?.split('=')[1];
            const r = await fetch(url, {method, headers: {'Content-Type': 'application/json', 'X-CSRFToken': token},
                                         body: body === null ? undefined : JSON.stringify(body)});
            return r.status;
        }""",
        [method, url, body],
    )


def test_a_reviewer_assigns_and_the_annotator_works_through_the_queue(live_server, new_page, studio, takes, screenshots):
    from segmentation.models import Review, ReviewEvent

    first, second, third = takes
    project = studio["project"]

    # rachel (reviewer) assigns the first two takes to ann from the capture list.
    rachel = new_page("rachel")
    rachel.get_by_test_id("filter-project").select_option(str(project.pk))
    rachel.get_by_test_id(f"select-{first.pk}").check()
    rachel.get_by_test_id(f"select-{second.pk}").check()
    rachel.get_by_test_id("assign-to-ann").check()
    rachel.get_by_test_id("assign-go").click()
    expect(rachel.get_by_test_id(f"team-{first.pk}")).to_have_text("ann assigned")
    expect(rachel.get_by_test_id(f"team-{third.pk}")).to_have_text("—")

    # ann's queue: the two takes, oldest first, with duration and candidate count.
    ann = new_page("ann")
    ann.get_by_test_id("nav-queue").click()
    rows = ann.get_by_test_id("queue-rows").locator("tr")
    expect(rows).to_have_count(2)
    expect(rows.nth(0)).to_contain_text(first.name)
    expect(rows.nth(0)).to_contain_text("12.0 s")
    expect(rows.nth(0)).to_contain_text(str(len(first.latest_finished_run().candidates)))
    ann.get_by_test_id(f"queue-open-{first.pk}").click()

    # Label the first segment, then "submit and open next" lands on the second take.
    expect(ann.get_by_test_id("capture-name")).to_have_text(first.name)
    ann.keyboard.press("1")
    expect(ann.get_by_test_id("save-state")).to_have_text("Saved")
    ann.get_by_test_id("submit-next").click()
    ann.get_by_test_id("confirm-ok").click()
    expect(ann.get_by_test_id("capture-name")).to_have_text(second.name)
    assert Review.objects.get(capture=first, annotator=studio["ann"]).status == "submitted"

    # rachel returns ann's review of the first take with a comment.
    rachel.goto(f"{live_server.url}/captures/{first.pk}/")
    ann_review = Review.objects.get(capture=first, annotator=studio["ann"])
    rachel.get_by_test_id("review-picker").select_option(str(ann_review.pk))
    rachel.get_by_test_id("return-review").click()
    rachel.get_by_test_id("prompt-text").fill("The first segment is a walk only up to the turn.")
    rachel.get_by_test_id("prompt-ok").click()
    expect(rachel.get_by_test_id("return-review")).to_be_hidden()
    assert Review.objects.get(pk=ann_review.pk).status == "returned"

    # ann sees it in the queue with the comment, edits and resubmits.
    ann.get_by_test_id("nav-queue").click()
    expect(ann.get_by_test_id(f"queue-item-{first.pk}")).to_have_attribute("data-state", "returned")
    expect(ann.get_by_test_id(f"queue-comment-{first.pk}")).to_have_text("The first segment is a walk only up to the turn.")
    # Opening the second take started nothing (reading a review never writes one).
    expect(ann.get_by_test_id(f"queue-item-{second.pk}")).to_have_attribute("data-state", "assigned")
    ann.evaluate("document.querySelector('.toasts')?.replaceChildren()")  # a clean picture
    ann.screenshot(path=str(screenshots / "queue.png"))
    ann.get_by_test_id(f"queue-open-{first.pk}").click()
    expect(ann.get_by_test_id("readonly-banner")).to_contain_text("walk only up to the turn")
    ann.keyboard.press("2")
    expect(ann.get_by_test_id("save-state")).to_have_text("Saved")
    expect(ann.get_by_test_id("submit")).to_have_text("Resubmit")
    ann.get_by_test_id("submit").click()
    ann.get_by_test_id("confirm-ok").click()
    expect(ann.get_by_test_id("submit")).to_have_text("Submitted")
    actions = list(ReviewEvent.objects.filter(review=ann_review).values_list("action", flat=True))
    assert actions[-3:] == ["return", "label", "resubmit"]

    # The dashboard shows who is assigned and each review's state.
    rachel.get_by_test_id("nav-dashboard").click()
    expect(rachel.get_by_test_id("dash-captures")).to_contain_text("ann submitted")
    assert ann.errors == [] and rachel.errors == []


def test_an_annotator_cannot_assign_return_or_see_another_queue(live_server, new_page, studio, takes):
    from segmentation.models import Assignment, Review

    first = takes[0]
    project = studio["project"]
    bob_review = Review.objects.create(capture=first, annotator=studio["bob"], status="submitted")
    ann = new_page("ann")
    ann.get_by_test_id("filter-project").select_option(str(project.pk))
    ann.get_by_test_id(f"select-{first.pk}").check()
    expect(ann.get_by_test_id("assign-bar")).to_have_text("Only the project's reviewers and admins assign captures.")
    assert fetch(ann, "POST", f"/api/projects/{project.pk}/assignments/",
                 {"captures": [first.pk], "annotators": ["ann"]}) == 403
    assert fetch(ann, "POST", f"/api/captures/{first.pk}/reviews/{bob_review.pk}/return/",
                 {"comment": "redo"}) == 403
    assert fetch(ann, "GET", f"/api/queue/?project={project.pk}&user=bob") == 403
    ann.goto(f"{live_server.url}/queue/?project={project.pk}")
    expect(ann.get_by_test_id("queue-user")).to_have_count(0)
    assert not Assignment.objects.exists()
    assert Review.objects.get(pk=bob_review.pk).status == "submitted"


def test_a_reviewer_unassigns_and_reassigns_from_a_members_queue(live_server, new_page, studio, takes):
    from segmentation.models import Assignment
    from segmentation.services.assignments import do_assign

    first = takes[0]
    project = studio["project"]
    do_assign(project, studio["alice"], [first.pk], ["ann"])
    rachel = new_page("rachel")
    rachel.goto(f"{live_server.url}/queue/?project={project.pk}&user=ann")
    expect(rachel.get_by_test_id(f"queue-item-{first.pk}")).to_have_attribute("data-state", "assigned")
    rachel.get_by_test_id(f"reassign-{first.pk}").select_option("bob")
    expect(rachel.get_by_test_id(f"queue-item-{first.pk}")).to_have_count(0)
    assert Assignment.objects.get(capture=first).annotator == studio["bob"]
    rachel.get_by_test_id("queue-user").select_option("bob")
    rachel.get_by_test_id(f"unassign-{first.pk}").click()
    expect(rachel.get_by_test_id(f"queue-item-{first.pk}")).to_have_count(0)
    assert not Assignment.objects.exists()


def test_each_capture_goes_to_n_annotators_spread_evenly(live_server, new_page, studio, takes):
    from segmentation.models import Assignment

    project = studio["project"]
    rachel = new_page("rachel")
    rachel.get_by_test_id("filter-project").select_option(str(project.pk))
    for capture in takes[:2]:
        rachel.get_by_test_id(f"select-{capture.pk}").check()
    rachel.get_by_test_id("assign-to-ann").check()
    rachel.get_by_test_id("assign-to-bob").check()
    rachel.get_by_test_id("assign-per-capture").fill("1")
    rachel.get_by_test_id("assign-go").click()
    expect(rachel.get_by_test_id(f"team-{takes[0].pk}")).not_to_have_text("—")
    expect(rachel.get_by_test_id(f"team-{takes[1].pk}")).not_to_have_text("—")
    per_person = sorted(Assignment.objects.filter(annotator__username=u).count() for u in ("ann", "bob"))
    assert per_person == [1, 1]
    assert all(c.assignments.count() == 1 for c in takes[:2])


def test_a_project_can_keep_annotators_to_their_assignments(live_server, new_page, studio, takes):
    project = studio["project"]
    alice = new_page("alice")
    alice.goto(f"{live_server.url}/projects/{project.pk}/team/")
    alice.get_by_test_id("pick-unassigned").uncheck()
    expect(alice.locator(".toast")).to_contain_text("only what is assigned")
    project.refresh_from_db()
    assert project.annotators_pick_unassigned is False

    ann = new_page("ann")
    ann.goto(f"{live_server.url}/captures/{takes[2].pk}/")
    expect(ann.get_by_test_id("review-refused")).to_contain_text("is not assigned to you")
    ann.get_by_role("link", name="← My queue").click()
    expect(ann.get_by_test_id("queue-rows")).to_contain_text("Nothing is assigned yet.")
