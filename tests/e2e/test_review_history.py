"""A review's history kept by the server: undo and redo go on after a reload, and the
annotator restores the review as it was at an earlier entry of the activity log, a
restore that is itself an entry undo takes back."""

from playwright.sync_api import expect

from tests.e2e.test_review_page import ReviewScreen, cut_by_id


def test_undo_survives_a_reload_and_the_activity_log_restores_an_earlier_point(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    first, second = sorted(screen.review()["cuts"], key=lambda c: c["frame"])[:2]

    # Accept the first candidate (this starts the review), delete the second.
    page.keyboard.press("Home")
    page.keyboard.press("Shift+ArrowRight")
    page.keyboard.press("a")
    screen.saved()
    page.keyboard.press("Shift+ArrowRight")
    page.keyboard.press("d")
    screen.saved()
    ids = {c["candidate_frame"]: c["id"] for c in screen.review()["cuts"]}
    c0, c1 = ids[first["frame"]], ids[second["frame"]]
    fates = lambda: (cut_by_id(screen.review(), c0)["fate"], cut_by_id(screen.review(), c1)["fate"])  # noqa: E731
    assert fates() == ("accepted", "deleted")

    # After a reload the page still knows what undo takes back.
    page.reload()
    screen.wait_ready()
    expect(page.get_by_test_id("undo")).to_be_enabled()
    expect(page.get_by_test_id("redo")).to_be_disabled()
    page.keyboard.press("z")
    screen.saved()
    assert fates() == ("accepted", "pending")
    page.keyboard.press("z")
    screen.saved()
    assert fates() == ("pending", "pending")
    page.keyboard.press("Shift+Z")
    screen.saved()
    assert fates() == ("accepted", "pending")
    assert [(e["action"], e["after"]["intent"]) for e in screen.events()[-3:]] == [
        ("restore", "undo"), ("restore", "undo"), ("restore", "redo")]
    # The screen shows the server's answer: the second candidate is pending again.
    expect(page.get_by_test_id("stats").locator(".stat-deleted b")).to_have_text("0")

    # Restore the review as it was when it was created, from the activity log.
    created = screen.events()[0]
    assert created["action"] == "create"
    page.get_by_test_id(f"restore-event-{created['id']}").click()
    expect(page.get_by_role("dialog")).to_contain_text("Restore this point of the activity?")
    page.get_by_test_id("confirm-ok").click()
    screen.saved()
    assert fates() == ("pending", "pending")
    last = screen.events()[-1]
    assert (last["action"], last["after"]["event"], last["after"]["intent"], last["user"]) == ("restore", created["id"], None, "ann")
    expect(page.get_by_test_id("events").locator("li").first).to_have_attribute("data-action", "restore")
    expect(page.get_by_test_id("stats").locator(".stat-accepted b")).to_have_text("0")

    # The restore is a step of the history, after a reload too: undo takes it back.
    page.reload()
    screen.wait_ready()
    page.keyboard.press("z")
    screen.saved()
    assert fates() == ("accepted", "pending")
    assert page.errors == []


def test_a_reviewer_restores_an_annotators_review_from_its_log_and_another_annotator_cannot(live_server, new_page, ingested_capture, studio):
    ann = new_page("ann")
    screen = ReviewScreen(ann, live_server.url, ingested_capture)
    screen.open()
    ann.keyboard.press("Home")
    ann.keyboard.press("Shift+ArrowRight")
    ann.keyboard.press("d")
    screen.saved()
    review = screen.review()
    deleted = next(c for c in review["cuts"] if c["fate"] == "deleted")
    created = screen.events()[0]
    restore_url = f"{live_server.url}/api/captures/{ingested_capture.pk}/reviews/{review['id']}/restore/"

    # bob, another annotator of the project, is refused; nothing changes.
    bob = new_page("bob")
    refused = bob.request.post(restore_url, data={"event": created["id"], "version": review["version"]})
    assert refused.status == 403
    assert screen.review()["version"] == review["version"]

    # rachel, a reviewer, picks ann's review, sees its log and restores its first entry.
    rachel = new_page("rachel")
    rachel.goto(f"{live_server.url}/captures/{ingested_capture.pk}/")
    rachel.get_by_test_id("review-picker").select_option(label="ann (read-only)")
    expect(rachel.locator("h3", has_text="Activity of ann's review")).to_be_visible()
    rachel.get_by_test_id(f"restore-event-{created['id']}").click()
    rachel.get_by_test_id("confirm-ok").click()
    expect(rachel.locator(".toast").last).to_contain_text("Restored ann's review.")
    assert cut_by_id(screen.review(), deleted["id"])["fate"] == "pending"
    last = screen.events()[-1]
    assert (last["action"], last["user"], last["after"]["event"]) == ("restore", "rachel", created["id"])
    expect(rachel.get_by_test_id("events").locator("li").first).to_have_attribute("data-action", "restore")
    assert rachel.errors == [] and ann.errors == []
