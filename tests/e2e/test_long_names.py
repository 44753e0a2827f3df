"""Long names at laptop sizes: a studio's real capture names, label names near their bound, a
large taxonomy and long usernames must not push a page or a table past the screen, and text
cut short keeps its full wording in a tooltip (a title), at 1280x720 and 1440x900."""

import pytest
from playwright.sync_api import expect

# Long but valid: an export's file name as studios write them, label names near their
# 100-character bound, and a username of an e-mail-like kind (Django allows @ . + - _).
LONG_CAPTURE = ("2026-11-30_north-stage_session-04_MarthaVanDenBerghe-Okonkwo_take-017_"
                "walk-to-run-transition_carrying-crate_markers-relabelled_retake-after-dropout_"
                "v3_final.bvh")
LONG_USER = "margarethe.van-den-berghe-okonkwo.mocap-annotation@studio-north.example"
LONG_LABELS = [
    "reach overhead to the top shelf with both hands while stepping forward onto the left foot",
    "crouching walk under the low beam carrying the crate in both hands, looking back over",
    "turn on the spot to the right, stop, then step back two paces and lower the crate to the floor",
]
# A taxonomy of forty labels, the kind a studio builds over a year.
MANY_LABELS = [f"{verb} {how}" for verb in ("walk", "run", "jog", "sidestep", "crawl")
               for how in ("forward", "backward", "left", "right", "in a circle",
                           "carrying a crate", "with a limp", "on uneven ground")]

# What a person would see go wrong on a page: the page scrolls sideways, a table runs past
# the screen or out of its panel, or text is cut short with no tooltip to read it in full.
OVERFLOWS = """() => {
  const vw = innerWidth, found = [];
  const page = document.documentElement.scrollWidth;
  if (page > vw) found.push(`the page is ${page} px wide`);
  for (const t of document.querySelectorAll("table")) {
    const r = t.getBoundingClientRect();
    if (!r.width) continue;
    const panel = t.parentElement.getBoundingClientRect();
    const what = `table.${[...t.classList].join(".")}${t.dataset.testid ? "#" + t.dataset.testid : ""}`;
    if (r.right > vw + 0.5) found.push(`${what} ends at ${Math.round(r.right)} px`);
    if (r.right > panel.right + 0.5) found.push(`${what} runs out of its panel by ${Math.round(r.right - panel.right)} px`);
  }
  const side = document.querySelector(".side")?.getBoundingClientRect();
  for (const el of document.querySelectorAll(".side *")) {
    const r = el.getBoundingClientRect();
    if (r.width && r.right > side.right + 0.5)
      found.push(`"${el.textContent.trim().slice(0, 40)}" runs out of the side panel by ${Math.round(r.right - side.right)} px`);
  }
  for (const el of document.querySelectorAll("td, td *, .topbar *, .side *, .adj-row > *")) {
    if (el.children.length || !el.textContent.trim()) continue;
    const style = getComputedStyle(el);
    const clips = el.scrollWidth > el.clientWidth + 1 && style.overflowX !== "visible";
    if (clips && !(el.closest("[title]")?.title || "").includes(el.textContent.trim()))
      found.push(`"${el.textContent.trim().slice(0, 40)}…" is cut short with no tooltip`);
    // A name may give way; a word of the page's own ("Captures", "Adjudication") may not.
    if (clips && el.closest(".crumbs") && el.textContent.trim().length <= 16)
      found.push(`the crumb "${el.textContent.trim()}" is cut short`);
  }
  return found;
}"""


@pytest.fixture
def long_names(studio, ingested_capture):
    """The demo studio with a long-named take, a long-named annotator and a large taxonomy
    of long labels; the annotator and ann have both submitted a review of the take."""
    from django.contrib.auth import get_user_model

    from segmentation import services
    from segmentation.services.assignments import do_assign
    from tests.segmentation.test_library import submit_review

    get_user_model().objects.create_user(LONG_USER, password=f"{LONG_USER}-password")
    services.do_set_member(studio["project"], LONG_USER, "annotator")
    for name in LONG_LABELS + MANY_LABELS:
        services.do_add_label(studio["project"], name, "#64748b")
    ingested_capture.name = LONG_CAPTURE
    ingested_capture.save(update_fields=["name"])
    user = get_user_model().objects.get(username=LONG_USER)
    do_assign(studio["project"], studio["alice"], [ingested_capture.pk], [LONG_USER])
    submit_review(ingested_capture, user, [1200, 2400], [*LONG_LABELS])
    submit_review(ingested_capture, studio["ann"], [1300, 2400], ["walk", LONG_LABELS[1], "kick"])
    return {"capture": ingested_capture, "user": user}


SIZES = [(1280, 720), (1440, 900)]


@pytest.mark.parametrize(("width", "height"), SIZES)
def test_no_table_runs_past_the_screen_with_long_names(live_server, new_page, studio, long_names,
                                                      screenshots, width, height):
    capture, project = long_names["capture"], studio["project"].pk
    page = new_page("alice", width=width, height=height)
    problems = {}
    for path, ready in [("/", "capture-row"), ("/library/", "segment-rows"),
                        (f"/projects/{project}/team/", "member-"),
                        (f"/projects/{project}/dashboard/", None),
                        (f"/captures/{capture.pk}/adjudicate/", None)]:
        page.goto(f"{live_server.url}{path}")
        page.wait_for_load_state("networkidle")
        if ready:
            page.locator(f"[data-testid^={ready}]").first.wait_for()
        name = path.strip("/").replace("/", "-") or "captures"
        page.screenshot(path=str(screenshots / f"long-{name}-{width}.png"))
        found = page.evaluate(OVERFLOWS)
        if found:
            problems[path] = found
    assert problems == {}, "\n".join(f"{k}: {v}" for k, v in problems.items())
    assert page.errors == []


@pytest.mark.parametrize(("width", "height"), SIZES)
def test_the_annotators_queue_and_review_page_fit_with_long_names(live_server, new_page, studio,
                                                                 long_names, screenshots, width,
                                                                 height):
    capture = long_names["capture"]
    page = new_page(LONG_USER, width=width, height=height)
    problems = {}
    page.goto(f"{live_server.url}/queue/")
    expect(page.locator("table.queue")).to_contain_text("2026-11-30_north-stage")
    problems["/queue/"] = page.evaluate(OVERFLOWS)
    page.screenshot(path=str(screenshots / f"long-queue-{width}.png"))
    page.goto(f"{live_server.url}/captures/{capture.pk}/")
    expect(page.get_by_test_id("capture-name")).to_have_text(LONG_CAPTURE)
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    problems["review"] = page.evaluate(OVERFLOWS)
    page.screenshot(path=str(screenshots / f"long-review-{width}.png"))
    # The top bar's buttons are on the screen, whole.
    box = page.get_by_test_id("submit").bounding_box() if page.get_by_test_id("submit").count() else None
    logout = page.get_by_test_id("logout").bounding_box()
    assert logout["x"] + logout["width"] <= width, logout
    assert box is None or box["x"] + box["width"] <= width, box
    problems = {k: v for k, v in problems.items() if v}
    assert problems == {}, "\n".join(f"{k}: {v}" for k, v in problems.items())
    assert page.errors == []
