"""The timeline at studio length, driven with the mouse: on a 10-minute and a 60-minute
take (13_29's motion repeated, ~80 and ~470 candidates) a click or a drag on the time
ruler seeks and never edits the review, even right over a candidate; a cut is grabbed
only on its own handle."""

import re

import pytest
from playwright.sync_api import expect

from tests.e2e.long_takes import repeated_capture


def open_long_take(page, base_url, capture):
    """Open the review page and wait until the first pose and every lane at full resolution are drawn."""
    page.goto(f"{base_url}/captures/{capture.pk}/")
    expect(page.get_by_test_id("viewport")).to_have_attribute("data-first-pose-ms", re.compile(r"^\d+$"))
    expect(page.get_by_test_id("timeline")).to_have_attribute("data-lanes-ms", re.compile(r"^\d+$"), timeout=60_000)


def frame_shown(page):
    return int(page.get_by_test_id("hud-frame").inner_text().split()[1])


# Columns of the overview strip (the canvas's last 26 px) showing a pending candidate's amber tick.
AMBER_OVERVIEW_COLUMNS = """() => {
    const c = document.querySelector("[data-testid=timeline] canvas");
    const dpr = c.width / c.clientWidth;
    const top = Math.round((c.clientHeight - 26) * dpr);
    const d = c.getContext("2d").getImageData(0, top, c.width, Math.round(9 * dpr)).data;
    const columns = new Set();
    for (let i = 0; i < d.length; i += 4) {
        if (d[i] > 230 && d[i + 1] > 170 && d[i + 1] < 230 && d[i + 2] < 90) columns.add((i / 4) % c.width);
    }
    return columns.size / dpr;
}"""


def server_review(page, base_url, capture):
    response = page.request.get(f"{base_url}/api/captures/{capture.pk}/review/")
    assert response.ok, response.text()
    return response.json()


@pytest.mark.parametrize("minutes", [10, 60])
def test_a_click_or_drag_on_the_ruler_seeks_and_never_edits(live_server, new_page, studio, shared_data, minutes):
    capture = repeated_capture(studio["project"], studio["alice"], minutes * 60)
    page = new_page("ann")
    open_long_take(page, live_server.url, capture)
    before = server_review(page, live_server.url, capture)
    candidates = sorted(c["frame"] for c in before["cuts"])
    n = capture.n_frames

    # The whole take: twenty clicks on the ruler, each right over a candidate's marker.
    page.get_by_test_id("zoom-fit").click()
    box = page.locator("[data-testid=timeline] canvas").bounding_box()
    per_px = n / box["width"]
    ruler_y = box["y"] + 20
    for frame in candidates[:: max(1, len(candidates) // 20)][:20]:
        page.mouse.click(box["x"] + frame / n * box["width"], ruler_y)
        assert abs(frame_shown(page) - frame) <= per_px + 1, f"a click over the candidate at {frame} did not seek"

    # A drag along the ruler from a candidate scrubs to where the pointer ends.
    page.mouse.move(box["x"] + candidates[0] / n * box["width"], ruler_y)
    page.mouse.down()
    page.mouse.move(box["x"] + box["width"] * 0.6, ruler_y, steps=12)
    page.mouse.up()
    assert abs(frame_shown(page) - n * 0.6) <= per_px + 1

    # Zoomed in, clicks across the ruler still only seek.
    for _ in range(3):
        page.get_by_test_id("zoom-in").click()
    shown = []
    for i in range(1, 11):
        page.mouse.click(box["x"] + box["width"] * i / 11, ruler_y)
        shown.append(frame_shown(page))
    assert shown == sorted(shown) and len(set(shown)) == 10

    # Nothing reached the server: the review was never even started.
    expect(page.get_by_test_id("save-state")).to_have_text("Saved")
    after = server_review(page, live_server.url, capture)
    assert after["status"] == "not_started"
    assert [(c["frame"], c["fate"]) for c in after["cuts"]] == [(c["frame"], c["fate"]) for c in before["cuts"]]
    assert page.errors == []


def test_an_hour_long_take_has_an_overview_and_a_working_window(live_server, new_page, studio, shared_data, screenshots):
    capture = repeated_capture(studio["project"], studio["alice"], 60 * 60, name="13_29_one_hour.bvh")
    page = new_page("ann")
    open_long_take(page, live_server.url, capture)
    timeline = page.get_by_test_id("timeline")
    box = page.locator("[data-testid=timeline] canvas").bounding_box()
    n = capture.n_frames

    def x_of(frame):
        start, span = (int(timeline.get_attribute(f"data-view-{k}")) for k in ("start", "span"))
        return box["x"] + (frame - start) / span * box["width"]

    # It opens on a one-minute working window, its candidates drawn one by one.
    expect(timeline).to_have_attribute("data-view-span", str(60 * 120))
    expect(timeline).to_have_attribute("data-dense-cuts", "false")
    # The overview strip shows the whole hour's pending candidates meanwhile (~470, ticks in
    # as many pixel columns but where two share one).
    assert page.evaluate(AMBER_OVERVIEW_COLUMNS) > 300
    page.screenshot(path=str(screenshots / "long-take-window.png"))

    # A click on the overview seeks there, and the working window follows the playhead.
    overview_y = box["y"] + box["height"] - 12
    page.mouse.click(box["x"] + box["width"] * 0.75, overview_y)
    assert abs(frame_shown(page) - n * 0.75) <= n / box["width"] + 1
    start, span = (int(timeline.get_attribute(f"data-view-{k}")) for k in ("start", "span"))
    assert start <= frame_shown(page) <= start + span

    # A cut is grabbed on its handle: a click selects it, a small wobble moves nothing, a drag moves it.
    review = server_review(page, live_server.url, capture)
    cut = min((c for c in review["cuts"] if start < c["frame"] < start + span - 600), key=lambda c: c["frame"])
    handle_y = box["y"] + 32
    page.mouse.move(x_of(cut["frame"]), handle_y)
    page.mouse.down()
    page.mouse.move(x_of(cut["frame"]) + 3, handle_y, steps=3)
    page.mouse.up()
    expect(page.get_by_test_id("selected-cut")).to_contain_text(f"Cut at {cut['frame']}")
    assert server_review(page, live_server.url, capture)["status"] == "not_started"
    page.mouse.move(x_of(cut["frame"]), handle_y)
    page.mouse.down()
    page.mouse.move(x_of(cut["frame"] + 240), handle_y, steps=6)
    page.mouse.up()
    expect(page.get_by_test_id("save-state")).to_have_text("Saved")
    moved = next(c for c in server_review(page, live_server.url, capture)["cuts"] if c["candidate_frame"] == cut["frame"])
    assert moved["fate"] == "moved" and abs(moved["frame"] - (cut["frame"] + 240)) <= span / box["width"] + 1

    # "Fit" shows the whole hour: the candidates become ticks, not a wall of lines.
    page.get_by_test_id("zoom-fit").click()
    expect(timeline).to_have_attribute("data-view-span", str(n))
    expect(timeline).to_have_attribute("data-dense-cuts", "true")
    page.mouse.move(box["x"] + box["width"] * 0.3, box["y"] + 60)
    page.screenshot(path=str(screenshots / "long-take-overview.png"))
    assert page.errors == []
