"""Comments and segment attributes on the review page (issue 49, items 4 and 5), driven as
people do: an admin defines the attributes on the Team page; an annotator comments at the
playhead with C, a reviewer replies from the side panel, M and Shift+M move the playhead
to the comments, and the attribute letters set values on the segment under the playhead.
Every result is read back from the server; another annotator is refused."""

from playwright.sync_api import expect

from tests.e2e.test_review_page import ReviewScreen


def define_attributes(page, base_url, project):
    page.goto(f"{base_url}/projects/{project.pk}/team/")
    for name, kind, options, key in (("quality", "choice", "good, usable, unusable", "q"),
                                     ("needs cleanup", "boolean", "", "b")):
        page.get_by_test_id("new-attribute-name").fill(name)
        page.get_by_test_id("new-attribute-kind").select_option(kind)
        page.get_by_test_id("new-attribute-options").fill(options)
        page.get_by_test_id("new-attribute-hotkey").select_option(key)
        page.get_by_test_id("add-attribute").click()
        expect(page.get_by_test_id(f"attribute-row-{name}")).to_be_visible()
    schema = page.request.get(f"{base_url}/api/projects/{project.pk}/attributes/").json()
    assert [(a["name"], a["kind"], a["options"], a["hotkey"]) for a in schema] == [
        ("quality", "choice", ["good", "usable", "unusable"], "q"), ("needs cleanup", "boolean", [], "b")]


def write_in_prompt(page, text, ok):
    page.get_by_test_id("prompt-text").fill(text)
    expect(page.get_by_test_id("prompt-ok")).to_have_text(ok)
    page.get_by_test_id("prompt-ok").click()


def test_comments_and_attributes_from_the_keyboard(live_server, new_page, ingested_capture, studio):
    base = live_server.url
    define_attributes(new_page("alice"), base, studio["project"])

    ann = new_page("ann")
    screen = ReviewScreen(ann, base, ingested_capture)
    screen.open()
    # Ten frames on, twice: the playhead at frame 20; C comments there.
    ann.keyboard.press(".")
    ann.keyboard.press(".")
    assert screen.frame_shown() == 20
    ann.keyboard.press("c")
    write_in_prompt(ann, "left foot slides from here", "Comment")
    expect(ann.get_by_test_id("thread-20")).to_contain_text("left foot slides from here")
    comments_url = f"{base}/api/captures/{ingested_capture.pk}/comments/"
    [thread] = ann.request.get(comments_url).json()
    assert (thread["frame"], thread["anchor"], thread["author"], thread["parent"]) == (20, "frame", "ann", None)

    # A reviewer opens the capture: the thread is in the side panel; she replies.
    rachel = new_page("rachel")
    ReviewScreen(rachel, base, ingested_capture).open()
    expect(rachel.get_by_test_id("thread-20")).to_contain_text("on ann's review")
    rachel.get_by_test_id("thread-20").get_by_test_id("comment-reply-button").click()
    write_in_prompt(rachel, "cut just before it", "Reply")
    expect(rachel.get_by_test_id("thread-20").get_by_test_id("comment-reply")).to_contain_text("cut just before it")
    replies = [c for c in ann.request.get(comments_url).json() if c["parent"] == thread["id"]]
    assert [(c["author"], c["text"]) for c in replies] == [("rachel", "cut just before it")]

    # Another annotator reads none of it, on the page or through the API.
    bob = new_page("bob")
    ReviewScreen(bob, base, ingested_capture).open()
    expect(bob.get_by_test_id("comments")).to_contain_text("No comments")
    assert bob.request.get(comments_url).json() == []
    assert bob.request.get(f"{base}/api/captures/{ingested_capture.pk}/reviews/{thread['review']}/comments/").status == 404

    # M jumps from the start to the comment, Shift+M back finds none before it.
    ann.keyboard.press("Home")
    assert screen.frame_shown() == 0
    ann.keyboard.press("m")
    expect(ann.get_by_test_id("hud-frame")).to_contain_text("20")
    assert screen.frame_shown() == 20
    ann.keyboard.press("Shift+M")
    expect(ann.locator(".toast").last).to_contain_text("No comment before frame 20")

    # Q steps the quality of the segment under the playhead: good, then usable; B says it
    # needs cleanup; a click picks "unusable" on another segment.
    ann.reload()
    screen.wait_ready()
    ann.keyboard.press("q")
    screen.saved()
    ann.keyboard.press("q")
    screen.saved()
    ann.keyboard.press("b")
    screen.saved()
    review = screen.review()
    first = review["segments"][0]
    assert first["attributes"] == {"quality": "usable", "needs cleanup": True}
    expect(ann.get_by_test_id("attribute-quality-usable")).to_have_class("btn btn-small active")
    ann.keyboard.press("End")
    ann.get_by_test_id("attribute-quality-unusable").click()
    screen.saved()
    last = screen.review()["segments"][-1]
    assert last["attributes"] == {"quality": "unusable"}
    # Shift+C comments on the segment under the playhead: pinned to its start.
    ann.keyboard.press("Shift+C")
    write_in_prompt(ann, "whole segment is noisy", "Comment")
    expect(ann.get_by_test_id(f"thread-{last['start']}")).to_contain_text("(segment)")
    on_segment = [c for c in ann.request.get(comments_url).json() if c["anchor"] == "segment"]
    assert [(c["frame"], c["text"]) for c in on_segment] == [(last["start"], "whole segment is noisy")]
    actions = [(e["action"], e["after"]) for e in screen.events() if e["action"] == "attribute"]
    assert actions[0] == ("attribute", {"index": 0, "attribute": "quality", "value": "good"})
    assert len(actions) == 4

    # Labelled and submitted, the segment is in the library: the attribute filter finds it
    # and its row shows its values.
    ann.keyboard.press("Home")
    ann.keyboard.press("1")
    screen.saved()
    ann.get_by_test_id("submit").click()
    ann.get_by_test_id("confirm-ok").click()
    expect(ann.get_by_test_id("readonly-banner")).to_contain_text("You submitted this review")
    ann.goto(f"{base}/library/")
    ann.get_by_test_id("lib-attribute").fill("quality:usable")
    ann.get_by_test_id("lib-attribute").press("Enter")
    expect(ann.get_by_test_id("segment-attributes")).to_have_text("quality: usable · needs cleanup")
    assert "attribute=quality%3Ausable" in ann.url
    found = ann.request.get(f"{base}/api/segments/?attribute=quality:usable").json()
    assert [(r["start"], r["label"]) for r in found["results"]] == [(0, "walk")]
    assert ann.errors == [] and rachel.errors == []
