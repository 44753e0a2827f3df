"""What a first-time studio user trips over, checked where they would see it: the review page
at laptop sizes, the submit dialog, the library's filters and export progress, the capture
list's upload and assignment."""

import time

import pytest
from playwright.sync_api import expect

from tests.e2e.test_review_page import ReviewScreen

# Where an element sits against the viewport, and whether the page scrolls sideways.
FITS = """(selector) => {
  const el = document.querySelector(selector);
  const r = el.getBoundingClientRect();
  return { left: r.left, right: r.right, top: r.top, bottom: r.bottom, width: innerWidth, height: innerHeight,
           scrollWidth: document.documentElement.scrollWidth };
}"""


# The oldest entry of the edit history: is it what a person sees at its centre (not clipped
# away by a panel that does not scroll)?
LAST_EVENT = """() => {
  const li = document.querySelector("[data-testid=events] li:last-child");
  const r = li.getBoundingClientRect();
  const seen = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
  return { top: r.top, bottom: r.bottom, height: r.height, seen: !!seen && li.contains(seen) };
}"""
# The demo project's taxonomy has 15 labels; a studio's is rarely smaller.
MORE_LABELS = ["run", "jump", "arm circles", "idle", "knee raise", "twist", "side reach",
               "side bend", "toe touch", "turn"]


@pytest.mark.parametrize(("width", "height"), [(1280, 720), (1440, 900)])
def test_the_review_page_fits_a_laptop_screen_with_its_history_in_reach(
        live_server, new_page, ingested_capture, studio, screenshots, width, height):
    from segmentation import services

    for name in MORE_LABELS:
        services.do_add_label(studio["project"], name, "#64748b")
    page = new_page("ann", width=width, height=height)
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    for _ in range(12):  # a history longer than the panel
        page.keyboard.press("ArrowRight")
        page.keyboard.press("i")
    screen.saved()
    expect(page.get_by_test_id("events").locator("li")).to_have_count(13)
    if (width, height) == (1280, 720):  # the README's
        page.screenshot(path=str(screenshots / "review-1280x720.png"))
    side = page.evaluate(FITS, ".side")
    assert side["scrollWidth"] <= width, side
    assert side["right"] <= width and side["bottom"] <= height, side
    # Scrolled to with the mouse wheel over the side panel, as a person would, the oldest
    # entry of the history is on the screen.
    page.mouse.move(side["right"] - 40, side["bottom"] - 40)
    for _ in range(6):
        page.mouse.wheel(0, 600)
        page.wait_for_timeout(100)
    last = page.evaluate(LAST_EVENT)
    assert last["seen"] and last["height"] > 0, last
    assert 0 <= last["top"] and last["bottom"] <= height, last
    # The top bar's buttons keep to one line.
    assert page.get_by_test_id("submit").bounding_box()["height"] < 40
    assert page.errors == []


def test_the_submit_dialog_says_the_pending_candidates_will_be_kept(live_server, new_page,
                                                                   ingested_capture, studio):
    from segmentation.models import LibrarySegment

    page = new_page("ann")
    screen = ReviewScreen(page, live_server.url, ingested_capture)
    screen.open()
    pending = len(ingested_capture.latest_finished_run().candidates)
    page.get_by_test_id("submit").click()
    dialog = page.get_by_role("dialog")
    expect(dialog.get_by_test_id("submit-pending")).to_contain_text(
        f"{pending} pending candidates will be kept as cuts")
    expect(dialog.get_by_test_id("submit-unlabelled")).to_contain_text(
        f"{pending + 1} unlabelled segments will be left out of the library")
    expect(page.get_by_test_id("confirm-ok")).to_have_text(f"Submit, keeping {pending}")
    page.get_by_test_id("confirm-ok").click()
    expect(page.get_by_test_id("readonly-banner")).to_contain_text("You submitted this review")
    kept = [c for c in screen.review()["cuts"] if c["fate"] != "deleted"]
    assert len(kept) == pending  # as the dialog said
    assert not LibrarySegment.objects.filter(capture=ingested_capture).exists()
    assert page.errors == []


# Every table on the page, and the page itself, against the viewport's width.
WIDTHS = """() => ({
  page: document.documentElement.scrollWidth,
  tables: [...document.querySelectorAll("table")].map((t) => Math.ceil(t.getBoundingClientRect().right)),
  viewport: innerWidth,
})"""


@pytest.mark.parametrize("width", [1280, 1440])
def test_no_page_is_wider_than_a_laptop_screen(live_server, new_page, ingested_capture, studio,
                                               width):
    from tests.segmentation.test_library import submit_review

    submit_review(ingested_capture, studio["ann"], [1200, 2400], ["walk", "jumping_jack", None])
    page = new_page("alice", width=width, height=800)
    project = studio["project"].pk
    for path, ready in [("/", "capture-row"), ("/library/", "segment-rows"),
                        (f"/projects/{project}/team/", None),
                        (f"/projects/{project}/dashboard/", None),
                        (f"/captures/{ingested_capture.pk}/adjudicate/", None)]:
        page.goto(f"{live_server.url}{path}")
        page.wait_for_load_state("networkidle")
        if ready:
            page.locator(f"[data-testid^={ready}]").first.wait_for()
        widths = page.evaluate(WIDTHS)
        assert widths["page"] <= width and all(r <= width for r in widths["tables"]), (path, widths)
    assert page.errors == []


# The top bar's links, in order, by test id.
NAV = """() => [...document.querySelectorAll("header.topbar [data-testid^=nav-], header.topbar [data-testid=logout]")]
  .map((el) => el.dataset.testid)"""


def test_every_page_has_the_same_navigation(live_server, new_page, ingested_capture, studio):
    from tests.segmentation.test_library import submit_review

    submit_review(ingested_capture, studio["ann"], [1200, 2400], ["walk", "jumping_jack", None])
    project = studio["project"].pk
    page = new_page("alice")
    expected = ["nav-queue", "nav-library", "nav-dashboard", "nav-team", "nav-user", "logout"]
    for path in ["/", "/queue/", "/library/", f"/captures/{ingested_capture.pk}/",
                 f"/captures/{ingested_capture.pk}/adjudicate/", f"/projects/{project}/dashboard/",
                 f"/projects/{project}/team/"]:
        page.goto(f"{live_server.url}{path}")
        expect(page.get_by_test_id("nav-user")).to_have_text("alice")
        assert page.evaluate(NAV) == expected, path
    assert page.errors == []


def test_an_annotator_is_offered_no_page_that_would_refuse_them(live_server, new_page,
                                                               ingested_capture, studio):
    """The dashboard and the team page are for the project's reviewers and admins: an
    annotator's top bar leaves them out on every page, rather than leading to an error."""
    page = new_page("ann")
    expected = ["nav-queue", "nav-library", "nav-user", "logout"]
    for path in ["/", "/queue/", "/library/", f"/captures/{ingested_capture.pk}/"]:
        page.goto(f"{live_server.url}{path}")
        expect(page.get_by_test_id("nav-user")).to_have_text("ann")
        assert page.evaluate(NAV) == expected, path
    assert page.errors == []


def test_a_newcomer_creates_a_project_and_uploads_point_takes_until_ready(live_server,
                                                                         new_page, studio):
    """dora, signed in with no project, creates one from the capture list (becoming its
    admin); a Vicon C3D, a Qualisys TSV and a Kinect joint CSV chosen in the page's file
    dialog are each uploaded to it, and each row turns ready once a worker has read it."""
    from django.contrib.auth import get_user_model

    from segmentation import tasks
    from segmentation.models import Capture, DetectionRun, Project
    from tests.motionlib.points_data import points_file

    dora = get_user_model().objects.create_user("dora", password="dora-password")
    paths = [points_file("hdm05", "HDM_bd_05-01_01_120.c3d"),
             points_file("vmci", "subject1_run1.tsv"), points_file("utkinect", "s01_e01.csv")]
    page = new_page("dora")
    page.get_by_test_id("new-project").click()
    page.get_by_test_id("prompt-text").fill("Dora's mocap")
    page.get_by_test_id("prompt-ok").click()
    project = page.get_by_test_id("filter-project")
    expect(project.locator("option:checked")).to_have_text("Dora's mocap")
    created = Project.objects.get(name="Dora's mocap")
    assert created.role_of(dora) == "admin"
    expect(page.get_by_test_id("nav-team")).to_be_visible()  # her project's admin pages

    expect(page.get_by_test_id("dropzone")).to_contain_text(".c3d")
    page.locator("input[type=file]").set_input_files([str(p) for p in paths])
    uploads = page.get_by_test_id("uploads")
    for path in paths:  # each gets its progress row at once, then they go one at a time
        expect(uploads).to_contain_text(path.name)
    expect(page.locator(".toast-error")).to_have_count(0)
    deadline = time.monotonic() + 30
    while Capture.objects.count() < len(paths) and time.monotonic() < deadline:
        time.sleep(0.2)
    captures = {c.name: c for c in Capture.objects.filter(project=created)}
    assert sorted(captures) == sorted(p.name for p in paths)
    for capture in captures.values():  # the worker's jobs, run here in-process
        tasks.ingest(capture.pk)
        for run in DetectionRun.objects.filter(capture=capture, status="queued"):
            tasks.detect(run.pk)
    for capture in captures.values():
        row = page.get_by_test_id(f"capture-{capture.pk}")
        expect(row.locator(".badge")).to_have_text("ready", timeout=30_000)
    assert page.errors == []


def test_the_capture_list_speaks_to_a_first_upload(live_server, new_page, ingested_capture,
                                                  studio):
    """The drop zone names every format taken; a file that can never parse offers no Retry;
    with one project, assigning does not ask for it."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services, tasks
    from tests.e2e.conftest import synthetic_bvh

    content = synthetic_bvh(seed=8, duration=10.0)
    upload = SimpleUploadedFile("cut_short.bvh", content[: len(content) // 2 - 7])
    broken, _ = services.do_upload_capture(studio["project"], studio["alice"], upload)
    tasks.ingest(broken.pk)
    page = new_page("rachel")
    expect(page.get_by_test_id("dropzone")).to_contain_text(".fbx")
    row = page.get_by_test_id(f"capture-{broken.pk}")
    expect(row).to_contain_text("failed")
    expect(row.get_by_test_id(f"fix-file-{broken.pk}")).to_contain_text("upload it")
    expect(row.get_by_test_id(f"retry-{broken.pk}")).to_have_count(0)
    # rachel reviews one project only: ticking a capture offers its annotators at once.
    page.get_by_test_id(f"select-{ingested_capture.pk}").check()
    page.get_by_test_id("assign-to-ann").check()
    page.get_by_test_id("assign-go").click()
    expect(page.get_by_test_id(f"team-{ingested_capture.pk}")).to_have_text("ann assigned")
    assert page.errors == []


def test_the_library_filters_by_annotator_and_shows_export_progress(live_server, new_page,
                                                                   ingested_capture, studio):
    from tests.segmentation.test_library import submit_review

    submit_review(ingested_capture, studio["ann"], [1200, 2400], ["walk", "squat", "kick"])
    submit_review(ingested_capture, studio["bob"], [2400], ["punch", "walk"])
    page = new_page("rachel")
    page.goto(f"{live_server.url}/library/?gold=false")
    annotator = page.get_by_test_id("lib-annotator")
    expect(annotator.locator("option")).to_have_text(
        ["Any annotator", "alice", "ann", "bob", "rachel"])
    annotator.select_option("bob")
    expect(page.get_by_test_id("segment-count")).to_have_text("2 segments")
    assert "annotator=bob" in page.url
    page.goto(f"{live_server.url}/library/?gold=false&annotator=ann")  # a link to the filter
    expect(page.get_by_test_id("segment-count")).to_have_text("3 segments")
    expect(page.get_by_test_id("lib-annotator")).to_have_value("ann")

    # Three glTF clips take Blender more than a second: the page says what is going on.
    page.get_by_test_id("export-format").select_option("glb")
    with page.expect_download(timeout=120_000) as download:
        page.get_by_test_id("export-zip").click()
        progress = page.get_by_test_id("export-progress")
        expect(progress).to_contain_text("Exporting 3 clips as glTF", timeout=10_000)
        expect(progress).to_contain_text("received")
    assert download.value.suggested_filename == "segments-glb.zip"
    expect(progress).to_have_count(0)
    assert page.errors == []
