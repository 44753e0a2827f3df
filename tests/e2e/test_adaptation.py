"""Adaptation in the browser: the review page says where its candidates came from, and a
reviewer re-detects an untouched capture from the capture list (an annotator is not
offered to)."""

import re

import pytest
from django.core.files.uploadedfile import SimpleUploadedFile
from playwright.sync_api import expect

from motionlib import synth
from segmentation import services, tasks
from segmentation.models import ProjectCutModel
from tests.e2e.conftest import synthetic_bvh
from tests.segmentation.base import ingested

SECONDS = 30.0


def ingest(studio, seed):
    """Upload a synthetic take and run the worker's jobs for it here, in-process."""
    upload = SimpleUploadedFile(f"session_{seed}.bvh", synthetic_bvh(seed=seed, duration=SECONDS))
    return ingested(studio["project"], studio["alice"], upload)


def review_to_the_truth(capture, user, seed):
    """``user`` replaces the candidates by the take's true boundaries and submits."""
    _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
    review = services.get_or_create_review(capture, user)
    for cut in list(review.cuts.all()):
        services.do_change_cut(review, user, cut, review.version, fate="deleted")
    for start, _stop, _label in segments[1:]:
        services.do_insert_cut(review, user, start, review.version)
    services.do_submit_review(review, user, review.version)


def test_the_review_page_says_the_candidates_are_not_adapted_yet(live_server, new_page, studio):
    capture = ingest(studio, seed=81)
    page = new_page("ann")
    page.goto(f"{live_server.url}/captures/{capture.pk}/")
    expect(page.get_by_test_id("adaptation-line")).to_have_text("Candidates not adapted yet (zero-shot detector).")


def test_the_review_page_says_how_many_reviewed_takes_the_candidates_came_from(live_server, new_page, studio):
    for seed in (82, 83):
        review_to_the_truth(ingest(studio, seed), studio["bob"], seed)
    job = ProjectCutModel.objects.get(project=studio["project"], status="queued")
    tasks.retrain(job.pk)
    assert ProjectCutModel.objects.get(pk=job.pk).version == 1
    capture = ingest(studio, seed=84)

    page = new_page("ann")
    page.goto(f"{live_server.url}/captures/{capture.pk}/")

    expect(page.get_by_test_id("adaptation-line")).to_have_text("Candidates adapted from 2 reviewed takes (model v1).")
    assert page.errors == []


def retrain(studio):
    """Run the project's queued training here, in-process, as a worker would."""
    job = ProjectCutModel.objects.get(project=studio["project"], status="queued")
    tasks.retrain(job.pk)
    return ProjectCutModel.objects.get(pk=job.pk)


def under_cut(studio, seed):
    """ann deletes every candidate of the take and inserts nothing."""
    review = services.get_or_create_review(ingest(studio, seed), studio["ann"])
    for cut in list(review.cuts.all()):
        services.do_change_cut(review, studio["ann"], cut, review.version, fate="deleted")
    services.do_submit_review(review, studio["ann"], review.version)


def test_the_review_page_says_why_a_retraining_was_refused_and_what_a_figure_was_measured_on(
        live_server, new_page, studio):
    # Issue 48, item 3: ann under-cuts the project's first four reviewed takes.
    for seed in (88, 89, 90, 91):
        under_cut(studio, seed)
    refused = retrain(studio)
    assert refused.version is None and refused.refused, refused.error
    waiting = ingest(studio, seed=93)

    # The gate's refusal is the project's news: its reviewers and admins read it, in the
    # panel's neutral text; an annotator is not told on every take.
    annotator = new_page("bob")
    annotator.goto(f"{live_server.url}/captures/{waiting.pk}/")
    expect(annotator.get_by_test_id("adaptation-line")).to_have_text("Candidates not adapted yet (zero-shot detector).")
    expect(annotator.get_by_test_id("adaptation-note")).to_have_count(0)
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{waiting.pk}/")
    note = page.get_by_test_id("adaptation-note")
    expect(note).to_have_text(f"Last retraining {refused.refused}. The project keeps the zero-shot detector.")
    expect(note).not_to_have_class(re.compile("error"))

    # bob's honest reviews are learnt; the figure says whose reviews it was measured on.
    for seed in (86, 87):
        review_to_the_truth(ingest(studio, seed), studio["bob"], seed)
    v1 = retrain(studio)
    assert v1.version == 1, v1.refused or v1.error
    capture = ingest(studio, seed=94)
    page.goto(f"{live_server.url}/captures/{capture.pk}/")
    expect(page.get_by_test_id("adaptation-line")).to_have_text("Candidates adapted from 2 reviewed takes (model v1).")
    figure = page.get_by_test_id("adaptation-figure")
    expect(figure).to_have_text(re.compile(
        r"Learnt from 2 reviewed takes; on 6 held-out reviewed takes \(all reviewed by one annotator alone each "
        r"\(2 annotators\)\) \d\.\d\d edits per cut, F1 \d\.\d\d\."))
    shown = [float(x) for x in re.findall(r"\d\.\d\d", figure.inner_text())]
    assert shown == pytest.approx([v1.held_out_edits_per_cut, v1.held_out_f1], abs=0.0051)  # rounded to 2 decimals
    assert page.errors == [] and annotator.errors == []


def test_a_reviewer_redetects_an_untouched_capture_from_the_list(live_server, new_page, studio):
    capture = ingest(studio, seed=85)
    annotator = new_page("ann")
    expect(annotator.get_by_test_id(f"capture-{capture.pk}")).to_contain_text("ready")
    expect(annotator.get_by_test_id(f"redetect-{capture.pk}")).to_have_count(0)

    page = new_page("rachel")
    page.get_by_test_id(f"redetect-{capture.pk}").click()

    expect(page.get_by_text("detecting again with the project's model")).to_be_visible()
    expect(page.get_by_test_id(f"capture-{capture.pk}")).to_contain_text("detecting…")
    expect(page.get_by_test_id(f"redetect-{capture.pk}")).to_have_count(0)
    run = capture.runs.order_by("-id").first()
    assert (run.status, run.created_by) == ("queued", studio["rachel"])
