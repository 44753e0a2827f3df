"""The review page end to end: an annotator edits a detected capture in the browser and
every edit lands in the database, survives a reload and shows in the audit log; another
annotator starts from an untouched review; a reviewer reads it without editing it."""


import pytest
from playwright.sync_api import expect


class ReviewScreen:
    """The review page as the test drives it: canvas geometry and API reads."""

    def __init__(self, page, base_url, capture):
        self.page, self.base_url, self.capture = page, base_url, capture

    def open(self):
        self.page.goto(f"{self.base_url}/captures/{self.capture.pk}/")
        self.wait_ready()

    def wait_ready(self):
        expect(self.page.get_by_test_id("capture-name")).to_have_text(self.capture.name)
        # Every chunk of positions arrived (the loader stamps how long it took).
        self.page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")

    def review(self):
        response = self.page.request.get(f"{self.base_url}/api/captures/{self.capture.pk}/review/")
        assert response.ok, response.text()
        return response.json()

    def events(self):
        return self.page.request.get(f"{self.base_url}/api/captures/{self.capture.pk}/review/events/").json()

    def saved(self):
        expect(self.page.get_by_test_id("save-state")).to_have_text("Saved")

    def box(self):
        return self.page.locator("[data-testid=timeline] canvas").bounding_box()

    def x(self, frame):
        """Page x of a frame while the timeline shows the whole take."""
        box = self.box()
        return box["x"] + frame / self.capture.n_frames * box["width"]

    def signal_y(self):
        return self.box()["y"] + 60

    def ruler_y(self):
        return self.box()["y"] + 12

    def frame_shown(self):
        text = self.page.get_by_test_id("hud-frame").inner_text()
        return int(text.split()[1])


def cut_by_id(review, cut_id):
    return next(c for c in review["cuts"] if c["id"] == cut_id)


def test_it_saves_every_edit_and_restores_the_review_exactly_after_reload(live_server, new_page, ingested_capture, studio, screenshots):
    page = new_page("ann")
    # The capture list shows the capture; opening it goes to the review page.
    row = page.get_by_test_id(f"capture-{ingested_capture.pk}")
    expect(row).to_contain_text("ready")
    row.click()
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.wait_ready()
    expect(page.get_by_test_id("hud-time")).to_contain_text("· 120 fps")

    # Opening the page starts no review: the server shows the one the first edit starts.
    start = screen.review()
    assert (start["id"], start["status"]) == (None, "not_started")
    assert {c["fate"] for c in start["cuts"]} == {"pending"}
    frames_per_px = ingested_capture.n_frames / screen.box()["width"]

    # Accept: click the dashed candidate line. The first edit starts the review.
    page.mouse.click(screen.x(min(c["frame"] for c in start["cuts"])), screen.signal_y())
    screen.saved()
    start = screen.review()
    c0, c1, c2, c3 = sorted(start["cuts"], key=lambda c: c["frame"])[:4]
    assert start["status"] == "in_progress" and c0["fate"] == "accepted"

    # Move: drag a candidate right, less than halfway to the next one.
    shift_px = min(20.0, (c2["frame"] - c1["frame"]) / 3 / frames_per_px)
    page.mouse.move(screen.x(c1["frame"]), screen.signal_y())
    page.mouse.down()
    for step in range(1, 6):
        page.mouse.move(screen.x(c1["frame"]) + shift_px * step / 5, screen.signal_y())
    page.mouse.up()
    screen.saved()
    moved = cut_by_id(screen.review(), c1["id"])
    assert moved["fate"] == "moved" and moved["candidate_frame"] == c1["frame"]
    assert abs(moved["frame"] - (c1["frame"] + shift_px * frames_per_px)) <= frames_per_px + 1

    # Delete: from the first frame, Shift+→ three times selects the third cut; D deletes it.
    page.keyboard.press("Home")
    for _ in range(3):
        page.keyboard.press("Shift+ArrowRight")
    expect(page.get_by_test_id("selected-cut")).to_contain_text(f"Cut at {c2['frame']}")
    page.keyboard.press("d")
    screen.saved()
    assert cut_by_id(screen.review(), c2["id"])["fate"] == "deleted"

    # Insert: scrub the ruler to between the fourth cut and the next one, press I.
    later = [c["frame"] for c in start["cuts"] if c["frame"] > c3["frame"]]
    target = (c3["frame"] + (min(later) if later else ingested_capture.n_frames)) // 2
    page.mouse.click(screen.x(target), screen.ruler_y())
    inserted_at = screen.frame_shown()
    assert abs(inserted_at - target) <= frames_per_px + 1
    page.keyboard.press("i")
    screen.saved()
    inserted = [c for c in screen.review()["cuts"] if c["origin"] == "inserted"]
    assert [(c["frame"], c["fate"]) for c in inserted] == [(inserted_at, "accepted")]

    # Label: hotkey 2 labels the segment under the playhead; a click labels the first one.
    page.keyboard.press("2")
    screen.saved()
    page.keyboard.press("Home")
    page.get_by_test_id("label-walk").click()
    screen.saved()
    segments = {s["start"]: s["label"] for s in screen.review()["segments"]}
    assert segments[0] == "walk" and segments[inserted_at] == "punch"

    # Undo takes the last label off; redo puts it back; both are saved on the server too.
    page.keyboard.press("z")
    screen.saved()
    assert screen.review()["segments"][0]["label"] is None
    page.keyboard.press("Shift+Z")
    screen.saved()
    before_reload = screen.review()
    assert before_reload["segments"][0]["label"] == "walk"

    page.reload()
    screen.wait_ready()
    after_reload = screen.review()
    assert after_reload == before_reload
    stats = page.get_by_test_id("stats")
    expect(stats).to_contain_text("2 of")
    expect(stats.locator(".stat-deleted b")).to_have_text("1")
    expect(stats.locator(".stat-inserted b")).to_have_text("1")

    # The database holds exactly what the page showed.
    from segmentation.models import Review

    stored = Review.objects.get(capture=ingested_capture, annotator=studio["ann"])
    fates = {c.id: (c.fate, c.frame) for c in stored.cuts.all()}
    assert fates[c0["id"]] == ("accepted", c0["frame"])
    assert fates[c1["id"]] == ("moved", moved["frame"])
    assert fates[c2["id"]][0] == "deleted"
    assert stored.version == after_reload["version"]

    # The audit log, in the API and on the page, shows each action in order; the undo and
    # the redo are restores the server made from the log.
    actions = [e["action"] for e in screen.events()]
    assert actions == ["create", "accept", "move", "delete", "insert", "label", "label", "restore", "restore"]
    shown = page.locator("[data-testid=events] li").evaluate_all("els => els.map(e => e.dataset.action)")
    assert shown == list(reversed(actions))

    # For the README: label two more segments by hotkey, then leave the playhead mid-take
    # on a selected cut, zoomed in a little.
    page.keyboard.press("Home")
    for key in ("3", "4"):
        page.keyboard.press("Shift+ArrowRight")
        page.keyboard.press(key)
        screen.saved()
    assert [s["label"] for s in screen.review()["segments"]][:3] == ["walk", "squat", "kick"]
    page.keyboard.press("Shift+ArrowRight")
    page.keyboard.press("ArrowRight")
    page.keyboard.press("Shift+ArrowLeft")
    page.get_by_test_id("zoom-in").click()
    page.mouse.move(300, 300)
    page.wait_for_timeout(300)
    page.screenshot(path=str(screenshots / "review.png"))
    assert page.errors == []

    # Another annotator gets an untouched review of their own.
    other = new_page("bob")
    bob = ReviewScreen(other, live_server.url, ingested_capture)
    bob.open()
    review = bob.review()
    assert review["annotator"]["username"] == "bob"
    assert {c["fate"] for c in review["cuts"]} == {"pending"}
    assert len(review["cuts"]) == len(start["cuts"])
    assert all(s["label"] is None for s in review["segments"])
    expect(other.get_by_test_id("stats").locator(".stat-pending b")).to_have_text(str(len(start["cuts"])))
    expect(other.get_by_test_id("review-picker")).to_have_count(0)
    assert other.errors == []


def test_it_lets_a_reviewer_read_an_annotators_review_without_editing_it(live_server, new_page, ingested_capture, studio):
    from segmentation import services

    review = services.get_or_create_review(ingested_capture, studio["ann"])
    first = review.cuts.order_by("frame").first()
    services.do_change_cut(review, studio["ann"], first, review.version, fate="deleted")

    page = new_page("rachel")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    page.get_by_test_id("review-picker").select_option(label="ann (read-only)")
    expect(page.get_by_test_id("readonly-banner")).to_contain_text("Viewing ann's review")
    expect(page.get_by_test_id("stats").locator(".stat-deleted b")).to_have_text("1")
    page.keyboard.press("i")
    expect(page.locator(".toast-error")).to_contain_text("read-only")
    review.refresh_from_db()
    assert review.version == 2 and review.cuts.count() == len(ingested_capture.latest_finished_run().candidates)
    assert page.errors == []


def test_it_shows_what_changed_when_the_review_was_edited_elsewhere(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    # The same annotator, in another tab, starts the review and deletes the first cut.
    from segmentation import services

    review = services.get_or_create_review(ingested_capture, studio["ann"])
    start = screen.review()
    first, second = sorted(start["cuts"], key=lambda c: c["frame"])[:2]
    services.do_change_cut(review, studio["ann"], review.cuts.get(pk=first["id"]), start["version"], fate="deleted")

    page.mouse.click(screen.x(second["frame"]), screen.signal_y())
    dialog = page.get_by_role("dialog")
    expect(dialog).to_contain_text("This review changed elsewhere")
    # It says what happened in words: no internal review id, and no "reload" (it already
    # shows the current version).
    expect(dialog.get_by_test_id("conflict-text")).to_have_text(
        "Your review was saved from another tab or window first. This page shows that version now.")
    expect(dialog).not_to_contain_text(f"review {start['id']}")
    expect(dialog).not_to_contain_text("reload")
    expect(dialog.get_by_test_id("conflict-changes")).to_contain_text(f"cut at frame {first['frame']} is deleted")
    expect(dialog.get_by_test_id("conflict-unsaved")).to_contain_text(f"accept cut at {second['frame']}")
    dialog.get_by_test_id("dialog-ok").click()
    # The page now shows the server's review; nothing was merged behind anyone's back.
    current = screen.review()
    assert cut_by_id(current, first["id"])["fate"] == "deleted"
    assert cut_by_id(current, second["id"])["fate"] == "pending"
    expect(page.get_by_test_id("stats").locator(".stat-deleted b")).to_have_text("1")
    assert page.errors == []


@pytest.mark.parametrize(("path", "title", "reason"), [
    ("/captures/999999/", "Not found", "No such capture."),
    ("/projects/{project}/dashboard/", "Not allowed", "Only the project's reviewers and admins"),
])
def test_it_explains_a_capture_that_does_not_exist_or_a_page_not_for_this_role(
        live_server, new_page, studio, path, title, reason):
    """A refusal says so, with the server's reason; it is not a failure ("Something went
    wrong") of the service."""
    page = new_page("ann")
    page.goto(f"{live_server.url}{path.format(project=studio['project'].pk)}")
    failure = page.get_by_test_id("page-failure")
    expect(failure.locator("h1")).to_have_text(title)
    expect(failure.locator("p")).to_contain_text(reason)
    expect(failure.locator(".error-text")).to_have_count(0)


def test_it_lists_the_shortcuts_and_locks_the_review_once_submitted(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    page.keyboard.press("?")
    help_box = page.get_by_test_id("help")
    for text in ("play / pause", "jump to previous / next cut", "undo", "redo", "label the segment"):
        expect(help_box).to_contain_text(text)
    page.keyboard.press("Escape")
    expect(help_box).to_have_count(0)

    # Shift+drag on the ruler loops a range; playback then stays inside it.
    n = ingested_capture.n_frames
    page.keyboard.down("Shift")
    page.mouse.move(screen.x(n * 0.25), screen.ruler_y())
    page.mouse.down()
    page.mouse.move(screen.x(n * 0.3), screen.ruler_y(), steps=4)
    page.mouse.up()
    page.keyboard.up("Shift")
    state = page.get_by_test_id("hud-state")
    expect(state).to_contain_text("loop")
    start, stop = (int(v) for v in state.inner_text().split("loop ")[1].split("–"))
    assert abs(start - n * 0.25) <= n / screen.box()["width"] + 1 and stop > start
    page.keyboard.press("Space")
    page.wait_for_timeout(1500)
    page.keyboard.press("Space")
    assert start <= screen.frame_shown() <= stop
    page.keyboard.press("l")
    expect(state).not_to_contain_text("loop")

    # Submitting asks first, saying what is still open; cancelling changes nothing.
    page.get_by_test_id("submit").click()
    expect(page.get_by_role("dialog")).to_contain_text("pending candidates will be kept as cuts")
    page.get_by_test_id("confirm-cancel").click()
    # Nothing was edited yet, so not even the review is started.
    assert screen.review()["status"] == "not_started"
    page.get_by_test_id("submit").click()
    page.get_by_test_id("confirm-ok").click()
    expect(page.get_by_test_id("readonly-banner")).to_contain_text("You submitted this review")
    assert screen.review()["status"] == "submitted"
    version = screen.review()["version"]
    page.keyboard.press("i")
    expect(page.locator(".toast-error")).to_contain_text("submitted")
    page.reload()
    screen.wait_ready()
    expect(page.get_by_test_id("submit")).to_be_disabled()
    assert screen.review()["version"] == version
    assert page.errors == []


def test_it_undoes_and_redoes_moves_inserts_and_deletes_on_the_server(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    start = screen.review()
    c0, c1 = sorted(start["cuts"], key=lambda c: c["frame"])[:2]

    # Move c0 with the mouse, delete c1 with the keyboard, insert a cut between them.
    page.mouse.move(screen.x(c0["frame"]), screen.signal_y())
    page.mouse.down()
    page.mouse.move(screen.x(c0["frame"]) + 12, screen.signal_y(), steps=4)
    page.mouse.up()
    screen.saved()
    # The move started the review: its candidates have ids now.
    ids = {c["candidate_frame"]: c["id"] for c in screen.review()["cuts"]}
    c0, c1 = ({**c, "id": ids[c["frame"]]} for c in (c0, c1))
    as_left = {ids[c["frame"]]: (c["fate"], c["frame"]) for c in start["cuts"]}
    page.keyboard.press("Home")
    page.keyboard.press("Shift+ArrowRight")
    page.keyboard.press("Shift+ArrowRight")
    page.keyboard.press("d")
    screen.saved()
    page.mouse.click(screen.x((c0["frame"] + c1["frame"]) // 2 + 40), screen.ruler_y())
    page.keyboard.press("i")
    screen.saved()
    edited = screen.review()
    assert cut_by_id(edited, c0["id"])["fate"] == "moved"
    assert cut_by_id(edited, c1["id"])["fate"] == "deleted"
    assert len([c for c in edited["cuts"] if c["origin"] == "inserted"]) == 1

    # Three undos bring every cut back to how it was: the inserted one ends deleted.
    for _ in range(3):
        page.keyboard.press("z")
        screen.saved()
    undone = screen.review()
    assert {c["id"]: (c["fate"], c["frame"]) for c in undone["cuts"] if c["origin"] == "candidate"} == as_left
    assert [c["fate"] for c in undone["cuts"] if c["origin"] == "inserted"] == ["deleted"]

    # Three redos bring the edits back, the inserted cut under its original id.
    for _ in range(3):
        page.keyboard.press("Shift+Z")
        screen.saved()
    redone = screen.review()
    assert {c["id"]: (c["fate"], c["frame"]) for c in redone["cuts"]} == {c["id"]: (c["fate"], c["frame"]) for c in edited["cuts"]}
    assert redone["segments"] == edited["segments"]

    # A deleted candidate stays on the ruler as a grey ×; clicking it restores the cut.
    page.get_by_test_id("zoom-fit").click()
    page.mouse.click(screen.x(c1["frame"]), screen.box()["y"] + 21)
    screen.saved()
    assert cut_by_id(screen.review(), c1["id"])["fate"] == "pending"
    assert screen.events()[-1]["action"] == "reset"
    assert page.errors == []
