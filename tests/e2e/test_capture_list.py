"""The capture list: drop files to upload them, watch their status change as the worker
gets to them, filter by status, project and name, and open one."""

import time

import pytest
from playwright.sync_api import expect

from segmentation.shared_data import data_dir
from tests.e2e.conftest import synthetic_bvh

SHARED_DATA = data_dir()

DROP = """([name, text]) => {
    const data = new DataTransfer();
    data.items.add(new File([text], name));
    const zone = document.querySelector("[data-testid=dropzone]");
    for (const type of ["dragover", "drop"]) {
        zone.dispatchEvent(new DragEvent(type, { dataTransfer: data, bubbles: true, cancelable: true }));
    }
}"""


DROP_MANY = """(files) => {
    const data = new DataTransfer();
    for (const [name, text] of files) data.items.add(new File([text], name));
    const zone = document.querySelector("[data-testid=dropzone]");
    zone.dispatchEvent(new DragEvent("drop", { dataTransfer: data, bubbles: true, cancelable: true }));
}"""


def open_list(new_page, username):
    """The capture list, once it has drawn its first answer (so drops are heard)."""
    page = new_page(username)
    expect(page.locator(".pager")).to_contain_text("capture")
    return page


def run_worker_jobs(attempts=20):
    """Do what a worker would: ingest queued captures, then run queued detections.

    The e2e conftest gives SQLite sessions a test database file, where writers wait for
    each other. If another folder's tests set the session's database up first it is
    shared-cache memory instead, where a write meets "table is locked" at once while the
    page's polling request reads: then wait and try again.
    """
    from django.db import OperationalError

    from segmentation import tasks
    from segmentation.models import Capture, DetectionRun

    for attempt in range(attempts):
        try:
            for capture in Capture.objects.filter(status="queued"):
                tasks.ingest(capture.pk)
            for run in DetectionRun.objects.filter(status="queued"):
                tasks.detect(run.pk)
            return
        except OperationalError as exc:
            if "locked" not in str(exc) or attempt == attempts - 1:
                raise
            time.sleep(0.25)


def test_it_uploads_dropped_files_and_shows_their_status_as_it_changes(live_server, new_page, studio):
    page = open_list(new_page, "ann")
    good = synthetic_bvh(seed=3, duration=12.0).decode()
    page.evaluate(DROP, ["warmup_short.bvh", good])
    page.evaluate(DROP, ["broken_take.bvh", "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 oops\n"])
    rows = page.get_by_test_id("capture-rows")
    expect(rows.locator("tr", has_text="warmup_short.bvh")).to_contain_text("queued")
    expect(rows.locator("tr", has_text="broken_take.bvh")).to_contain_text("queued")

    run_worker_jobs()
    # The list refreshes itself while anything is queued or processing.
    expect(rows.locator("tr", has_text="warmup_short.bvh")).to_contain_text("ready", timeout=20_000)
    broken = rows.locator("tr", has_text="broken_take.bvh")
    expect(broken).to_contain_text("failed")
    expect(broken.locator(".error-text")).not_to_be_empty()

    # Dropping the same file again is recognised as a duplicate, not a second capture.
    page.evaluate(DROP, ["warmup_short.bvh", good])
    expect(page.get_by_test_id("uploads")).to_contain_text("already uploaded")
    # A file that is not a capture is refused before anything is sent.
    page.evaluate(DROP, ["notes.txt", "hello"])
    expect(page.locator(".toast-error")).to_contain_text(
        "notes.txt: not a take Cutroom reads (.bvh, .fbx, .amc with its .asf, .c3d, .tsv or .csv).")
    expect(rows.locator("tr.capture-row")).to_have_count(2)

    page.get_by_test_id("filter-status").select_option("failed")
    expect(rows.locator("tr.capture-row")).to_have_count(1)
    expect(rows).to_contain_text("broken_take.bvh")
    assert "status=failed" in page.url
    page.get_by_test_id("filter-status").select_option("")
    page.get_by_test_id("filter-search").fill("warmup")
    page.wait_for_url("**/?search=warmup")
    expect(rows.locator("tr.capture-row")).to_have_count(1)
    expect(rows).to_contain_text("warmup_short.bvh")

    rows.locator("tr", has_text="warmup_short.bvh").click()
    expect(page.get_by_test_id("capture-name")).to_have_text("warmup_short.bvh")
    page.go_back()
    expect(page.get_by_test_id("filter-search")).to_have_value("warmup")
    assert page.errors == []


def test_it_retries_a_failed_capture_from_its_stored_original(live_server, new_page, studio):
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services
    from segmentation.models import Capture

    content = synthetic_bvh(seed=4, duration=8.0)
    capture, _ = services.do_upload_capture(studio["project"], studio["alice"], SimpleUploadedFile("lost_take.bvh", content))
    # Not the file's fault: the worker holding it was lost too often.
    Capture.objects.filter(pk=capture.pk).update(status="failed", error="the worker was lost 3 times")

    page = open_list(new_page, "ann")
    row = page.get_by_test_id(f"capture-{capture.pk}")
    expect(row).to_contain_text("the worker was lost 3 times")
    page.get_by_test_id(f"retry-{capture.pk}").click()
    expect(row).to_contain_text("queued")
    expect(page.get_by_test_id(f"retry-{capture.pk}")).to_have_count(0)
    assert page.url.rstrip("/") == live_server.url, "the click retried without opening the capture"

    run_worker_jobs()
    expect(row).to_contain_text("ready", timeout=20_000)
    with Capture.objects.get(pk=capture.pk).original.open("rb") as handle:
        assert handle.read() == content
    assert page.errors == []


def test_it_lists_only_captures_of_projects_the_user_belongs_to(live_server, new_page, studio):
    from django.contrib.auth import get_user_model
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services

    outsider = get_user_model().objects.create_user("olga", password="olga-password")
    elsewhere = services.do_create_project(outsider, "Olga's studio")
    services.do_upload_capture(elsewhere, outsider, SimpleUploadedFile("secret.bvh", synthetic_bvh(seed=1, duration=6.0)))
    services.do_upload_capture(studio["project"], studio["alice"], SimpleUploadedFile("shared.bvh", synthetic_bvh(seed=2, duration=6.0)))

    page = new_page("ann")
    rows = page.get_by_test_id("capture-rows")
    expect(rows.locator("tr.capture-row")).to_have_count(1)
    expect(rows).to_contain_text("shared.bvh")
    expect(page.get_by_test_id("filter-project").locator("option")).to_have_text(["All projects", "Studio A"])


def test_it_pairs_a_dropped_cmu_amc_with_its_asf_and_plays_the_real_take(live_server, new_page, studio):
    cmu = SHARED_DATA / "cmu"
    if not (cmu / "amc" / "13_29.amc").is_file():
        pytest.skip(f"real CMU captures not found under {cmu} (the shared/ folder beside the repository)")
    page = open_list(new_page, "ann")
    page.evaluate(DROP_MANY, [
        ["13_29.amc", (cmu / "amc" / "13_29.amc").read_text()],
        ["13.asf", (cmu / "asf" / "13.asf").read_text()],
    ])
    row = page.get_by_test_id("capture-rows").locator("tr", has_text="13_29.amc")
    expect(row).to_contain_text("queued", timeout=20_000)
    run_worker_jobs()
    expect(row).to_contain_text("ready", timeout=20_000)
    expect(row).to_contain_text("4,592")
    row.click()
    expect(page.get_by_test_id("capture-name")).to_have_text("13_29.amc")
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    page.keyboard.press("End")
    expect(page.get_by_test_id("hud-frame")).to_have_text("Frame 4591 / 4591")
    expect(page.get_by_test_id("hud-time")).to_contain_text("00:00:38:031 / 00:00:38:031 · 120 fps")
    assert page.errors == []
