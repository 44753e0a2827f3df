"""Adjudication end to end in the browser: two annotators' submitted reviews overlaid,
a reviewer starts the gold version from one of them, relabels a segment, saves it; the
gold version is in the database, the library prefers it and plays it in place, the
dashboard counts the capture as adjudicated, and an annotator cannot open the view."""


from playwright.sync_api import expect

from tests.segmentation.test_library import submit_review


def two_reviews(capture, studio):
    c0, c1, c2 = sorted(c["frame"] for c in capture.latest_finished_run().candidates)[:3]
    ann = submit_review(capture, studio["ann"], [c0, c1, c2], ["walk", "punch", "squat", "kick"])
    submit_review(capture, studio["bob"], [c0, c2], ["walk", "punch", "kick"])
    return ann, [c0, c1, c2]


def test_it_makes_a_gold_version_from_two_annotators_reviews(live_server, new_page, ingested_capture, studio, screenshots):
    from segmentation.models import Adjudication, LibrarySegment

    ann_review, cuts = two_reviews(ingested_capture, studio)
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    expect(page.get_by_test_id("adj-title")).to_have_text(f"Adjudicate {ingested_capture.name}")
    # Both annotators' versions are overlaid; their cuts at c0 and c2 agree exactly.
    expect(page.get_by_test_id("track-ann").locator(".tier-seg")).to_have_count(4)
    expect(page.get_by_test_id("track-bob").locator(".tier-seg")).to_have_count(3)
    expect(page.get_by_test_id("agreement-f1")).to_have_text("0.80")
    expect(page.get_by_test_id("gold-status")).to_have_text("Unsaved changes")
    # Disagreements are marked where they are: the cut only ann made, and the range
    # where ann says squat and bob says punch.
    expect(page.get_by_test_id("track-ann-cut-0")).to_have_attribute("data-mark", "agreed")
    expect(page.get_by_test_id("track-ann-cut-1")).to_have_attribute("data-mark", "lone")
    expect(page.get_by_test_id("label-conflict-0")).to_be_visible()

    page.get_by_test_id("use-ann").click()
    gold = page.get_by_test_id("track-gold")
    expect(gold.locator(".tier-seg")).to_have_count(4)
    gold.get_by_test_id("track-gold-seg-2").click()
    expect(page.get_by_test_id("gold-segment")).to_contain_text(f"frames {cuts[1]}–{cuts[2]}")
    page.get_by_test_id("gold-label").select_option("walk")
    expect(gold.get_by_test_id("track-gold-seg-2")).to_have_text("walk")
    page.get_by_test_id("save-gold").click()
    expect(page.get_by_test_id("gold-status")).to_have_text("Saved")
    page.screenshot(path=str(screenshots / "adjudication.png"))

    saved = Adjudication.objects.get(capture=ingested_capture)
    assert (saved.cuts, saved.label_names()) == (cuts, ["walk", "punch", "walk", "kick"])
    assert saved.version == 1 and saved.source_review_id == ann_review.pk
    assert saved.adjudicator.username == "rachel"

    # A reload shows the saved gold version, not a draft.
    page.reload()
    expect(page.get_by_test_id("gold-status")).to_have_text("Saved")
    expect(page.get_by_test_id("track-gold-seg-2")).to_have_text("walk")

    # The library prefers gold: only the four gold segments are listed, and one plays.
    page.get_by_test_id("nav-library").click()
    expect(page.get_by_test_id("segment-count")).to_have_text("4 segments")
    expect(page.locator(".gold-badge")).to_have_count(4)
    first = LibrarySegment.objects.filter(is_gold=True).order_by("-id").first()
    page.get_by_test_id(f"play-{first.pk}").click()
    expect(page.get_by_test_id("preview")).to_have_attribute("data-playing", str(first.pk))
    expect(page.get_by_test_id("preview-caption")).to_contain_text(f"frames {first.start}–{first.stop}")
    expect(page.locator("[data-testid=preview] canvas")).to_be_visible()
    # It plays: the drawing changes from one moment to the next.
    snapshot = "document.querySelector('[data-testid=preview] canvas').toDataURL()"
    page.wait_for_timeout(300)
    before = page.evaluate(snapshot)
    page.wait_for_timeout(400)
    assert page.evaluate(snapshot) != before
    page.screenshot(path=str(screenshots / "library.png"))
    # "Similar" lists the other gold segments, nearest first, by motion distance.
    page.get_by_test_id(f"similar-{first.pk}").click()
    similar_rows = page.locator("[data-testid=segment-rows] tr[data-testid^=segment-]")
    expect(similar_rows).to_have_count(3)
    expect(similar_rows.first).to_contain_text("d ")
    # Distances are headed as distances, and the count is of the similar clips shown.
    expect(page.get_by_test_id("metric-head")).to_have_text("Distance")
    expect(page.get_by_test_id("segment-count")).to_have_text("3 similar clips")

    page.goto(f"{live_server.url}/projects/{studio['project'].pk}/dashboard/")
    expect(page.get_by_test_id("state-adjudicated")).to_have_text("1")
    expect(page.get_by_test_id("dash-annotators")).to_contain_text("ann")
    page.screenshot(path=str(screenshots / "dashboard.png"))

    # A library row opens its capture's review page at the segment's first frame.
    page.goto(f"{live_server.url}/library/")
    page.get_by_test_id(f"segment-{first.pk}").get_by_role("link", name=ingested_capture.name).click()
    expect(page.get_by_test_id("hud-frame")).to_contain_text(f"Frame {first.start}")
    assert page.errors == []


def test_it_refuses_the_adjudication_view_to_an_annotator(live_server, new_page, ingested_capture, studio):
    two_reviews(ingested_capture, studio)
    page = new_page("bob")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    expect(page.get_by_text("Only the project's reviewers and admins see agreement")).to_be_visible()
    csrf = next(c["value"] for c in page.context.cookies() if c["name"] == "csrftoken")
    response = page.request.put(f"{live_server.url}/api/captures/{ingested_capture.pk}/adjudication/",
                                data={"cuts": [], "labels": ["walk"], "version": 0},
                                headers={"X-CSRFToken": csrf})
    assert response.status == 403, response.text()


def test_it_accepts_a_suggested_label_with_one_key(live_server, new_page, ingested_capture, studio):
    """Once the library has gold segments of one take, the segments of the next take
    come with suggested labels; S on the review page accepts the one under the playhead."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services, tasks
    from segmentation.models import Capture, DetectionRun
    from segmentation.services import gold
    from tests.e2e.conftest import synthetic_bvh

    # Take one (seed 5): punch | arm circles | squat | walk | punch | jumping jack | idle.
    cuts, labels = ([868, 1595, 2101, 2765, 3267, 3770],
                    ["punch", None, "squat", "walk", "punch", "jumping_jack", None])
    submit_review(ingested_capture, studio["ann"], cuts, labels)
    # Bob may not see ann's labels, only gold: rachel makes ann's review the gold version.
    gold.do_save_gold(ingested_capture, studio["rachel"], cuts, labels, version=0)
    # Take two (seed 6): squat | punch | squat | jumping jack | squat, cut but not labelled.
    upload = SimpleUploadedFile("second_session.bvh", synthetic_bvh(seed=6, duration=30.0))
    capture, _ = services.do_upload_capture(studio["project"], studio["alice"], upload)
    tasks.ingest(capture.pk)
    for run in DetectionRun.objects.filter(capture=capture, status="queued"):
        tasks.detect(run.pk)
    capture = Capture.objects.get(pk=capture.pk)
    review = services.get_or_create_review(capture, studio["bob"])
    for cut in list(review.cuts.all()):
        review = services.do_change_cut(review, studio["bob"], cut, review.version, fate="deleted")
    for frame in (645, 1302, 2256, 3040):
        review = services.do_insert_cut(review, studio["bob"], frame, review.version)
    # The worker's job, run here: suggestions are computed off the page's requests.
    tasks.suggest(capture.pk, studio["bob"].pk)

    page = new_page("bob")
    page.goto(f"{live_server.url}/captures/{capture.pk}/")
    expect(page.get_by_test_id("suggested-label")).to_have_text("suggested: squat (S accepts)")
    page.keyboard.press("s")
    expect(page.get_by_test_id("save-state")).to_have_text("Saved")
    segments = page.request.get(f"{live_server.url}/api/captures/{capture.pk}/review/").json()["segments"]
    assert segments[0]["label"] == "squat"
    body = page.request.get(f"{live_server.url}/api/captures/{capture.pk}/review/suggestions/").json()
    # A labelled segment needs no suggestion.
    assert [s["label"] for s in body["suggestions"]] == ["punch", "squat", "jumping_jack", "squat"]
    assert body["suggestions"][0]["start"] == 645
    assert page.errors == []


def test_tiers_feed_the_gold_tier_with_undo_snap_and_the_409_rule(live_server, new_page, ingested_capture, studio):
    from segmentation.models import Adjudication
    from segmentation.services.gold import do_save_gold

    _ann, (c0, c1, c2) = two_reviews(ingested_capture, studio)
    n = ingested_capture.n_frames
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    expect(page.get_by_test_id("viewport").locator("canvas")).to_be_visible()
    gold = page.get_by_test_id("track-gold")
    expect(gold.locator(".tier-seg")).to_have_count(1)
    page.keyboard.press("?")
    expect(page.get_by_test_id("help")).to_contain_text("take it into gold")
    page.keyboard.press("?")
    expect(page.get_by_test_id("help")).to_have_count(0)

    # A tier's cut, then a tier's segment (its bounds and its label), into gold.
    page.get_by_test_id("track-bob-cut-1").click()
    expect(gold.locator(".tier-cut")).to_have_count(1)
    page.get_by_test_id("track-ann-seg-1").click()
    expect(gold.locator(".tier-cut")).to_have_count(3)
    expect(gold.get_by_test_id("track-gold-seg-1")).to_have_text("punch")
    page.keyboard.press("z")
    expect(gold.locator(".tier-cut")).to_have_count(1)
    page.keyboard.press("Shift+Z")
    expect(gold.locator(".tier-cut")).to_have_count(3)
    expect(page.get_by_test_id("hud-frame")).to_contain_text(f"Frame {c0}")

    # Start over from bob's version (cuts c0, c2) and drag the c2 cut next to ann's c1:
    # it snaps onto c1 exactly.
    page.get_by_test_id("use-bob").click()
    expect(gold.locator(".tier-cut")).to_have_count(2)
    lane = gold.bounding_box()
    handle = page.get_by_test_id("gold-cut-handle-1").bounding_box()
    page.mouse.move(handle["x"] + handle["width"] / 2, handle["y"] + 10)
    page.mouse.down()
    page.mouse.move(lane["x"] + c1 / n * lane["width"] + 3, handle["y"] + 10, steps=5)
    page.mouse.up()
    expect(page.get_by_test_id("gold-selected-cut")).to_contain_text(f"at {c1}")
    # D deletes the selected gold cut; undo brings it back.
    page.keyboard.press("d")
    expect(gold.locator(".tier-cut")).to_have_count(1)
    page.keyboard.press("z")
    expect(gold.locator(".tier-cut")).to_have_count(2)
    page.get_by_test_id("save-gold").click()
    expect(page.get_by_test_id("gold-status")).to_have_text("Saved")
    assert Adjudication.objects.get(capture=ingested_capture).cuts == [c0, c1]

    # Someone else saves meanwhile: this page's next save is refused (409) and shows theirs.
    do_save_gold(ingested_capture, studio["alice"], [c2], ["walk", "kick"], version=1)
    page.get_by_test_id("track-ann-cut-2").click()
    page.get_by_test_id("save-gold").click()
    expect(page.get_by_role("dialog")).to_contain_text("alice saved gold version 2")
    page.get_by_test_id("dialog-ok").click()
    expect(gold.locator(".tier-cut")).to_have_count(1)
    saved = Adjudication.objects.get(capture=ingested_capture)
    assert (saved.version, saved.cuts) == (2, [c2])
    assert page.errors == []


def test_it_offers_a_retired_label_only_where_a_segment_already_carries_it(live_server, new_page, ingested_capture, studio):
    from segmentation.models import Adjudication
    from segmentation.services.taxonomy import do_change_label

    _, cuts = two_reviews(ingested_capture, studio)
    do_change_label(ingested_capture.project.labels.get(name="squat"), retired=True)
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    page.get_by_test_id("use-ann").click()
    gold = page.get_by_test_id("track-gold")
    # ann labelled [c1, c2) squat before it was retired: the segment keeps it.
    gold.get_by_test_id("track-gold-seg-2").click()
    chosen = page.get_by_test_id("gold-label").locator("option:checked")
    expect(chosen).to_have_text("squat (retired)")
    # Another segment is not offered it.
    gold.get_by_test_id("track-gold-seg-0").click()
    expect(page.get_by_test_id("gold-segment")).to_contain_text(f"frames 0–{cuts[0]}")
    options = page.get_by_test_id("gold-label").locator("option")
    expect(options).to_have_text(["(unlabelled)", "walk (1)", "punch (2)", "kick (4)", "jumping_jack (5)"])
    page.get_by_test_id("save-gold").click()
    expect(page.get_by_test_id("gold-status")).to_have_text("Saved")
    saved = Adjudication.objects.get(capture=ingested_capture)
    assert saved.label_names() == ["walk", "punch", "squat", "kick"]


def test_the_review_pages_navigation_keys_work_on_gold(live_server, new_page, ingested_capture, studio):
    """Alt+←/→ nudge the selected gold cut, U goes to the next unlabelled gold segment and G
    to a typed frame or timecode, as on the review page; the saved gold has the moves."""
    from segmentation.models import Adjudication

    _, (c0, c1, c2) = two_reviews(ingested_capture, studio)
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    page.get_by_test_id("use-ann").click()
    hud = page.get_by_test_id("hud-frame")

    page.get_by_test_id("gold-cut-handle-1").click()
    expect(page.get_by_test_id("gold-selected-cut")).to_contain_text(f"at {c1}")
    page.keyboard.press("Alt+ArrowRight")
    expect(page.get_by_test_id("gold-selected-cut")).to_contain_text(f"at {c1 + 1}")
    page.keyboard.press("Alt+Shift+ArrowLeft")
    expect(page.get_by_test_id("gold-selected-cut")).to_contain_text(f"at {c1 - 9}")
    expect(hud).to_contain_text(f"Frame {c1 - 9} ")

    # Clear the third segment's label; from the first frame U goes to it.
    page.keyboard.press("Escape")
    page.get_by_test_id("track-gold-seg-2").click()
    page.keyboard.press("0")
    expect(page.get_by_test_id("track-gold-seg-2")).to_have_text("")
    page.keyboard.press("Home")
    expect(hud).to_contain_text("Frame 0 ")
    page.keyboard.press("u")
    expect(hud).to_contain_text(f"Frame {c1 - 9} ")

    page.keyboard.press("g")
    field = page.get_by_test_id("prompt-line")
    expect(field).to_be_focused()
    field.fill("00:00:01:00")
    page.keyboard.press("Enter")
    expect(hud).to_contain_text(f"Frame {round(ingested_capture.fps)} ")
    page.keyboard.press("g")
    page.get_by_test_id("prompt-line").fill("not a frame")
    page.keyboard.press("Enter")
    expect(page.locator(".toasts")).to_contain_text("not a frame")
    expect(hud).to_contain_text(f"Frame {round(ingested_capture.fps)} ")

    page.get_by_test_id("save-gold").click()
    expect(page.get_by_test_id("gold-status")).to_have_text("Saved")
    saved = Adjudication.objects.get(capture=ingested_capture)
    assert saved.cuts == [c0, c1 - 9, c2]
    assert saved.label_names() == ["walk", "punch", None, "kick"]
    assert page.errors == []
