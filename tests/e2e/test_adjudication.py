"""Adjudication end to end in the browser: two annotators' submitted reviews overlaid,
a reviewer starts the gold version from one of them, relabels a segment, saves it; the
gold version is in the database, the library prefers it and plays it in place, the
dashboard counts the capture as adjudicated, and an annotator cannot open the view."""

from pathlib import Path

from playwright.sync_api import expect

from tests.segmentation.test_library import submit_review

SCREENSHOTS = Path(__file__).resolve().parents[2] / "docs" / "screenshots"


def two_reviews(capture, studio):
    c0, c1, c2 = sorted(c["frame"] for c in capture.latest_finished_run().candidates)[:3]
    ann = submit_review(capture, studio["ann"], [c0, c1, c2], ["walk", "punch", "squat", "kick"])
    submit_review(capture, studio["bob"], [c0, c2], ["walk", "punch", "kick"])
    return ann, [c0, c1, c2]


def test_it_makes_a_gold_version_from_two_annotators_reviews(live_server, new_page, ingested_capture, studio):
    from segmentation.models_library import Adjudication, LibrarySegment

    ann_review, cuts = two_reviews(ingested_capture, studio)
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    expect(page.get_by_test_id("adj-title")).to_have_text(f"Adjudicate {ingested_capture.name}")
    # Both annotators' versions are overlaid; their cuts at c0 and c2 agree exactly.
    expect(page.get_by_test_id("track-ann").locator(".adj-seg")).to_have_count(4)
    expect(page.get_by_test_id("track-bob").locator(".adj-seg")).to_have_count(3)
    expect(page.get_by_test_id("agreement-f1")).to_have_text("0.80")
    expect(page.get_by_test_id("gold-status")).to_have_text("Unsaved changes")

    page.get_by_test_id("use-ann").click()
    gold = page.get_by_test_id("track-gold")
    expect(gold.locator(".adj-seg")).to_have_count(4)
    gold.get_by_test_id("track-gold-seg-2").click()
    page.get_by_test_id("gold-label").select_option("walk")
    expect(gold.get_by_test_id("track-gold-seg-2")).to_have_text("walk")
    page.get_by_test_id("save-gold").click()
    expect(page.get_by_test_id("gold-status")).to_have_text("Saved")
    page.screenshot(path=str(SCREENSHOTS / "adjudication.png"))

    saved = Adjudication.objects.get(capture=ingested_capture)
    assert (saved.cuts, saved.labels) == (cuts, ["walk", "punch", "walk", "kick"])
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
    page.screenshot(path=str(SCREENSHOTS / "library.png"))

    page.goto(f"{live_server.url}/projects/{studio['project'].pk}/dashboard/")
    expect(page.get_by_test_id("state-adjudicated")).to_have_text("1")
    expect(page.get_by_test_id("dash-annotators")).to_contain_text("ann")
    assert page.errors == []


def test_it_refuses_the_adjudication_view_to_an_annotator(live_server, new_page, ingested_capture, studio):
    two_reviews(ingested_capture, studio)
    page = new_page("bob")
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/adjudicate/")
    expect(page.get_by_text("No such capture.")).to_be_visible()
    csrf = next(c["value"] for c in page.context.cookies() if c["name"] == "csrftoken")
    response = page.request.put(f"{live_server.url}/api/captures/{ingested_capture.pk}/adjudication/",
                                data={"cuts": [], "labels": ["walk"], "version": 0},
                                headers={"X-CSRFToken": csrf})
    assert response.status == 404, response.text()
