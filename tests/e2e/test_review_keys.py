"""The review page from the keyboard, as Label Studio, CVAT and ELAN users work: nudge the
selected cut by a frame or a step, go to the next pending candidate or unlabelled segment,
restore a deleted candidate, go to a typed frame or timecode. Each key is pressed for real
and what it did is read back from the server's review and audit log."""

from playwright.sync_api import expect

from tests.e2e.test_review_page import ReviewScreen, cut_by_id


def pending_after(review, frame):
    return min((c for c in review["cuts"] if c["fate"] == "pending" and c["frame"] > frame),
               key=lambda c: c["frame"])


def test_it_nudges_the_selected_cut_and_the_server_records_moves(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    first = pending_after(screen.review(), 0)

    # N selects the next pending candidate and puts the playhead on it.
    page.keyboard.press("n")
    expect(page.get_by_test_id("selected-cut")).to_contain_text(f"Cut at {first['frame']}")
    assert screen.frame_shown() == first["frame"]

    # Alt+→ nudges it one frame later: the first edit starts the review, as a move.
    page.keyboard.press("Alt+ArrowRight")
    screen.saved()
    review = screen.review()
    cut = next(c for c in review["cuts"] if c["candidate_frame"] == first["frame"])
    assert (cut["frame"], cut["fate"]) == (first["frame"] + 1, "moved")
    # Alt+Shift+← nudges it a step (10 frames) earlier.
    page.keyboard.press("Alt+Shift+ArrowLeft")
    screen.saved()
    assert cut_by_id(screen.review(), cut["id"])["frame"] == first["frame"] - 9
    assert screen.frame_shown() == first["frame"] - 9

    # The log has two moves of that candidate, from → to, and no delete or insert.
    events = screen.events()
    assert [e["action"] for e in events] == ["create", "move", "move"]
    assert [(e["cut"], e["before"]["frame"], e["after"]["frame"]) for e in events[1:]] == [
        (cut["id"], first["frame"], first["frame"] + 1),
        (cut["id"], first["frame"] + 1, first["frame"] - 9),
    ]
    # Alt+← stayed the page's: the browser did not go back.
    assert page.url.endswith(f"/captures/{ingested_capture.pk}/")
    assert page.errors == []


def test_it_goes_to_pending_and_unlabelled_and_restores_a_deleted_candidate(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    start = screen.review()
    c0 = pending_after(start, 0)
    c1 = pending_after(start, c0["frame"])

    # Accept the first candidate, then N skips it (no longer pending) to the second.
    page.keyboard.press("n")
    page.keyboard.press("a")
    screen.saved()
    page.keyboard.press("Home")
    page.keyboard.press("n")
    expect(page.get_by_test_id("selected-cut")).to_contain_text(f"Cut at {c1['frame']}")
    # Shift+N goes back to the previous pending candidate: none before c1 now.
    page.keyboard.press("Shift+N")
    expect(page.locator(".toast").last).to_contain_text(f"No pending candidate before frame {c1['frame']}")

    # D deletes it; R restores the deleted candidate nearest the playhead.
    page.keyboard.press("d")
    screen.saved()
    ids = {c["candidate_frame"]: c["id"] for c in screen.review()["cuts"]}
    assert cut_by_id(screen.review(), ids[c1["frame"]])["fate"] == "deleted"
    page.keyboard.press("Home")
    page.keyboard.press("r")
    screen.saved()
    assert cut_by_id(screen.review(), ids[c1["frame"]])["fate"] == "pending"
    assert screen.events()[-1]["action"] == "reset"
    assert screen.frame_shown() == c1["frame"]

    # Label the segment that starts at c1 (2 = punch), then U from the top goes to each
    # unlabelled segment in turn: c0's, then the one after c1's.
    page.keyboard.press("2")
    screen.saved()
    segments = screen.review()["segments"]
    unlabelled_starts = [s["start"] for s in segments if s["label"] is None and s["start"] > 0]
    assert c1["frame"] not in unlabelled_starts
    page.keyboard.press("Home")
    page.keyboard.press("u")
    assert screen.frame_shown() == unlabelled_starts[0] == c0["frame"]
    page.keyboard.press("u")
    assert screen.frame_shown() == unlabelled_starts[1]
    page.keyboard.press("Shift+U")
    assert screen.frame_shown() == c0["frame"]
    assert page.errors == []


def test_it_goes_to_a_typed_frame_or_timecode_and_shows_timecode(live_server, new_page, ingested_capture, studio):
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    hud_time = page.get_by_test_id("hud-time")
    last = ingested_capture.n_frames - 1
    # The read-out is the studio's timecode at the take's rate (120 fps: frames 000–119).
    expect(hud_time).to_contain_text(f"00:00:00:000 / 00:00:{last // 120:02d}:{last % 120:03d} · 120 fps")

    def go(text):
        page.keyboard.press("g")
        field = page.get_by_test_id("prompt-line")
        expect(field).to_be_focused()
        field.fill(text)
        page.keyboard.press("Enter")
        expect(field).to_have_count(0)

    go("00:00:10:034")
    expect(page.get_by_test_id("hud-frame")).to_contain_text(f"Frame {10 * 120 + 34} /")
    expect(hud_time).to_contain_text("00:00:10:034 /")
    go("250")
    expect(page.get_by_test_id("hud-frame")).to_contain_text("Frame 250 /")
    go("12:5")
    expect(page.get_by_test_id("hud-frame")).to_contain_text(f"Frame {12 * 120 + 5} /")

    # Bad input is named, and the playhead stays where it was.
    go("ten seconds")
    expect(page.locator(".toast-error")).to_contain_text('"ten seconds" is neither a frame number nor a timecode')
    go(str(last + 5))
    expect(page.locator(".toast-error").last).to_contain_text(f"past the take's last frame ({last}")
    assert screen.frame_shown() == 12 * 120 + 5

    # The help lists the new keys.
    page.keyboard.press("?")
    help_box = page.get_by_test_id("help")
    for text in ("nudge the selected cut one frame", "next / previous pending candidate",
                 "next / previous unlabelled segment", "restore the deleted candidate",
                 "go to a frame or a timecode"):
        expect(help_box).to_contain_text(text)
    assert page.errors == []
