"""Proposed labels on the review page (issue 47): a take detected with a model the project
trained on labelled reviews shows, in each unlabelled segment, the label its frame model
proposes (a dashed, italic look with the probability, never a label), S accepts it, and
only then does the server's review carry it; the submit dialog counts the proposals not
confirmed. An annotator's proposals are learnt from their own reviews and gold only: a
colleague with none of their own is proposed nothing."""

import re

from django.core.files.uploadedfile import SimpleUploadedFile
from playwright.sync_api import expect

from segmentation import tasks
from segmentation.models import ProjectCutModel
from tests.e2e.conftest import synthetic_bvh
from tests.e2e.test_review_page import ReviewScreen
from tests.segmentation.base import ingested
from tests.segmentation.truth_reviews import SECONDS, review_to_the_truth


def ingest(studio, seed):
    upload = SimpleUploadedFile(f"session_{seed}.bvh", synthetic_bvh(seed=seed, duration=SECONDS))
    return ingested(studio["project"], studio["alice"], upload)



def trained_take(studio):
    """bob reviews two takes; the project trains (the worker's job, run here); a third
    take is detected with the model and its run carries proposals."""
    for seed in (92, 93):
        review_to_the_truth(studio["project"], ingest(studio, seed), studio["bob"], seed)
    job = ProjectCutModel.objects.get(project=studio["project"], status="queued")
    tasks.retrain(job.pk)
    assert ProjectCutModel.objects.get(pk=job.pk).labels_model
    capture = ingest(studio, seed=94)
    run = capture.latest_finished_run()
    assert run.model_version == 1 and any(p["label"] for p in run.proposals), run.proposals
    return capture


def suggestions(page, base_url, capture):
    return page.request.get(f"{base_url}/api/captures/{capture.pk}/review/suggestions/").json()


def test_an_annotator_sees_a_proposal_accepts_it_with_s_and_the_dialog_counts_the_rest(
        live_server, new_page, studio, screenshots):
    capture = trained_take(studio)
    page = new_page("bob")
    screen = ReviewScreen(page, live_server.url, capture)
    screen.open()
    # The page asked for its suggestions; the worker's job runs here, the page polls.
    tasks.suggest(capture.pk, studio["bob"].pk)
    body = suggestions(page, live_server.url, capture)
    proposed = [s for s in body["suggestions"] if s["proposed"]]
    assert proposed and not body["pending"], body

    # Shift+→ walks the cuts until the segment under the playhead carries a proposal.
    shown = page.get_by_test_id("proposed-label")
    for _ in range(len(capture.latest_finished_run().candidates) + 1):
        if shown.count():
            break
        page.keyboard.press("Shift+ArrowRight")
        page.wait_for_timeout(150)
    expect(shown).to_have_text(re.compile(r"^\S+ proposed, \d+ % \(S accepts\)$"))
    label = shown.locator("i").inner_text()
    expect(page.get_by_test_id(f"label-{label}")).to_have_class(re.compile(r"\bproposed\b"))
    page.screenshot(path=str(screenshots / "review-proposed-labels.png"))
    start, stop = map(int, re.search(r"(\d+)–(\d+)", page.get_by_test_id("current-segment").inner_text()).groups())
    assert {"start": start, "stop": stop, "label": label} in [
        {k: s[k] for k in ("start", "stop", "label")} for s in proposed]
    # Nothing is written until the annotator accepts.
    assert screen.review()["id"] is None or all(seg["label"] is None for seg in screen.review()["segments"])

    page.keyboard.press("s")
    screen.saved()
    segments = screen.review()["segments"]
    assert [seg["label"] for seg in segments if seg["label"]] == [label]
    accepted = next(seg for seg in segments if seg["label"])
    assert (accepted["start"], accepted["stop"]) == (start, stop)
    expect(page.get_by_test_id("current-segment")).to_contain_text(f"labelled {label}")
    expect(shown).to_have_count(0)

    page.get_by_test_id("submit").click()
    dialog = page.get_by_role("dialog")
    rest = len(proposed) - 1
    expect(dialog.get_by_test_id("submit-proposed")).to_contain_text(
        f"{rest} proposed label{'s are' if rest != 1 else ' is'} not confirmed and will not be saved")
    page.keyboard.press("Escape")
    assert page.errors == []


def test_another_annotator_is_proposed_nothing_learnt_from_bobs_labels(live_server, new_page, studio):
    capture = trained_take(studio)
    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, capture)
    screen.open()
    tasks.suggest(capture.pk, studio["ann"].pk)
    body = suggestions(page, live_server.url, capture)
    assert [s for s in body["suggestions"] if s["label"]] == [], body
    runs = page.request.get(f"{live_server.url}/api/captures/{capture.pk}/runs/").json()
    assert all(run["proposals"] == [] for run in runs)
    for _ in range(len(capture.latest_finished_run().candidates) + 1):
        expect(page.get_by_test_id("proposed-label")).to_have_count(0)
        page.keyboard.press("Shift+ArrowRight")
    assert page.errors == []
