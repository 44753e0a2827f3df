"""The review page of a point take in Chromium: the joints of a Kinect take are drawn with the
links of its marker set, frames in which nothing was tracked (gaps) show nothing, and the
view draws the points again on the next tracked frame; the library offers C3D and CSV, per
segment and for the zip."""

import io
import re

import numpy as np
import pytest
from playwright.sync_api import expect

from tests.motionlib.points_data import points_file

# Joints and links are drawn light blue (left), orange (right) or near-white (centre) on a
# dark background with a dim grey floor grid: a bright pixel belongs to the body.
BRIGHT = 150
HUD_ROWS = 90  # the frame / time / state text over the top left of the view


def body_pixels(png: bytes) -> int:
    from PIL import Image

    image = np.asarray(Image.open(io.BytesIO(png)).convert("RGB"))
    return int((image[HUD_ROWS:].max(axis=2) > BRIGHT).sum())


@pytest.fixture
def kinect_capture(studio):
    from django.core.files.uploadedfile import SimpleUploadedFile

    from tests.segmentation.base import ingested

    path = points_file("utkinect", "s01_e01.csv")
    upload = SimpleUploadedFile(path.name, path.read_bytes())
    return ingested(studio["project"], studio["alice"], upload)


def open_at(page, base, capture, frame):
    page.goto(f"{base}/captures/{capture.pk}/?frame={frame}")
    expect(page.get_by_test_id("capture-name")).to_have_text(capture.name)
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    last = capture.n_frames - 1
    expect(page.get_by_test_id("hud-frame")).to_have_text(f"Frame {frame} / {last}")


def drawn(page):
    page.wait_for_timeout(300)  # the view renders on the next animation frame
    return body_pixels(page.locator("[data-testid=viewport] canvas").screenshot())


def test_it_draws_a_kinect_take_and_its_gaps(live_server, new_page, kinect_capture, screenshots):
    page = new_page("ann")
    # Frame 0 (frame id 190) is tracked; frames 1-3 have no row in the file.
    open_at(page, live_server.url, kinect_capture, 0)
    seen = drawn(page)
    assert seen > 200
    page.screenshot(path=str(screenshots / "review-points.png"))

    open_at(page, live_server.url, kinect_capture, 1)
    assert drawn(page) < seen / 10  # nothing tracked: no joints, no links

    # Opened on a gap, the view still follows the body once it is seen again.
    for _ in range(3):
        page.keyboard.press("ArrowRight")
    expect(page.get_by_test_id("hud-frame")).to_have_text(
        f"Frame 4 / {kinect_capture.n_frames - 1}")
    assert drawn(page) > seen / 2
    assert page.errors == []


def test_the_library_offers_c3d_and_csv_for_a_point_segment(live_server, new_page,
                                                           kinect_capture, studio):
    from segmentation.models import LibrarySegment
    from tests.segmentation.test_library import submit_review

    submit_review(kinect_capture, studio["ann"], [600], ["walk", None])
    segment = LibrarySegment.objects.get(capture=kinect_capture, start=0)
    page = new_page("ann")
    page.goto(f"{live_server.url}/library/")
    row = page.get_by_test_id(f"segment-{segment.pk}")
    expect(row).to_be_visible()
    expect(page.get_by_test_id(f"c3d-{segment.pk}")).to_have_attribute(
        "href", f"/api/segments/{segment.pk}/export.c3d")
    expect(page.get_by_test_id(f"csv-{segment.pk}")).to_be_visible()
    expect(page.get_by_test_id(f"fbx-{segment.pk}")).to_have_count(0)
    with page.expect_download() as download:
        page.get_by_test_id(f"c3d-{segment.pk}").click()
    assert download.value.suggested_filename.endswith("_walk_0-600.c3d")
    page.get_by_test_id("export-format").select_option("c3d")
    expect(page.get_by_test_id("export-zip")).to_have_attribute(
        "href", re.compile(r"file_format=c3d$"))
