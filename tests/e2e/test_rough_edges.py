"""Rough edges a new user hit, in the browser: an upload with "All projects" selected no
longer lands silently in the first project, and the dashboard is reachable from the
capture list and the review page."""

from playwright.sync_api import expect

from tests.e2e.conftest import synthetic_bvh
from tests.e2e.test_capture_list import DROP, open_list


def test_an_upload_with_all_projects_selected_asks_which_project(live_server, new_page, studio):
    from segmentation import services
    from segmentation.models import Capture

    other = services.do_create_project(studio["ann"], "Ann's own studio")
    page = open_list(new_page, "ann")
    take = synthetic_bvh(seed=3, duration=6.0).decode()
    page.evaluate(DROP, ["short.bvh", take])
    expect(page.locator(".toast-error")).to_contain_text("Choose the project to upload to")
    assert not Capture.objects.exists()

    page.get_by_test_id("filter-project").select_option(str(other.pk))
    page.evaluate(DROP, ["short.bvh", take])
    expect(page.get_by_test_id("uploads")).to_contain_text("uploaded")
    assert Capture.objects.get().project == other


def test_the_dashboard_is_reachable_from_the_capture_list_and_the_review_page(live_server, new_page, studio, ingested_capture):
    page = open_list(new_page, "rachel")
    page.get_by_test_id("nav-dashboard").click()
    expect(page.get_by_test_id("dash-captures")).to_contain_text(ingested_capture.name)
    page.goto(f"{live_server.url}/captures/{ingested_capture.pk}/")
    page.get_by_test_id("nav-dashboard").click()
    expect(page.get_by_test_id("dash-captures")).to_contain_text(ingested_capture.name)
    icon = page.evaluate("document.querySelector('link[rel=icon]').href")
    assert page.request.get(icon).status == 200
