"""A capture with as many joints as the service admits stays usable in the review page:
it loads, draws, and answers key presses promptly while it plays (issue 11, item 7)."""

import io

import numpy as np
import pytest
from playwright.sync_api import expect

# A frozen tab answers nothing for tens of seconds; a responsive one within a frame or two.
# The bound leaves room for a slow shared CI machine.
PROMPT_MS = 3000


def many_joint_bvh(n_joints, seed=7, duration=5.0):
    """A synthetic take (known body parts, so detection runs) with extra rotating joints
    hung off the root up to ``n_joints`` in all."""
    import motionlib
    from motionlib.skeleton import Skeleton

    take, _segments = motionlib.synth.generate(seed=seed, fps=120.0, duration=duration)
    sk = take.skeleton
    extra = n_joints - sk.n_joints
    rng = np.random.default_rng(seed)
    skeleton = Skeleton(
        names=[*sk.names, *(f"Marker{i}" for i in range(extra))],
        parents=[*sk.parents, *([0] * extra)],
        offsets=np.vstack([sk.offsets, rng.uniform(-20, 20, (extra, 3))]),
        channels=[*sk.channels, *([("Zrotation", "Yrotation", "Xrotation")] * extra)],
        rotation_orders=[*sk.rotation_orders, *(["ZYX"] * extra)],
        end_sites=sk.end_sites,
    )
    t = np.arange(take.n_frames)[:, None] / 120.0
    spin = np.round(30 * np.sin(t + rng.uniform(0, 6, extra * 3)), 2)
    channels = np.hstack([take.channels, spin])
    take = motionlib.take.Take(name="markers", format="bvh", fps=120.0, frame_time=1 / 120,
                               channels=channels, skeleton=skeleton)
    text = io.StringIO()
    motionlib.write_bvh(take, text)
    return text.getvalue().encode()


@pytest.fixture
def crowded_capture(studio, settings):
    from django.core.files.uploadedfile import SimpleUploadedFile

    from motionlib.take import DEFAULT_LIMITS
    from tests.segmentation.base import ingested

    n_joints = settings.CUTROOM_MAX_JOINTS or DEFAULT_LIMITS.max_joints
    upload = SimpleUploadedFile("markers.bvh", many_joint_bvh(n_joints))
    capture = ingested(studio["project"], studio["alice"], upload)
    assert capture.n_joints == n_joints
    return capture


def test_it_answers_keys_promptly_while_playing_the_most_joints_admitted(live_server, new_page, crowded_capture):
    page = new_page("ann")
    page.goto(f"{live_server.url}/captures/{crowded_capture.pk}/")
    expect(page.get_by_test_id("capture-name")).to_have_text(crowded_capture.name)
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    hud = page.get_by_test_id("hud-frame")
    last = crowded_capture.n_frames - 1

    page.keyboard.press("End")
    expect(hud).to_have_text(f"Frame {last} / {last}", timeout=PROMPT_MS)
    page.keyboard.press("Home")
    expect(hud).to_have_text(f"Frame 0 / {last}", timeout=PROMPT_MS)
    page.keyboard.press(" ")
    expect(hud).not_to_have_text(f"Frame 0 / {last}", timeout=PROMPT_MS)
    # While it plays, a key is still handled at once: pause, then step one frame.
    page.keyboard.press(" ")
    expect(page.get_by_test_id("hud-state")).to_contain_text("paused", timeout=PROMPT_MS)
    paused_at = int(hud.inner_text().split()[1])
    page.keyboard.press("ArrowRight")
    expect(hud).to_have_text(f"Frame {paused_at + 1} / {last}", timeout=PROMPT_MS)
    assert page.errors == []


def test_it_refuses_to_draw_more_joints_than_the_service_admits(live_server, new_page, crowded_capture):
    from segmentation.models import Capture

    # A capture stored before the limit was lowered: the page says why it draws no skeleton
    # and the timeline still works.
    skeleton = {**crowded_capture.skeleton, "joints": [f"j{i}" for i in range(30_000)],
                "parents": [-1, *([0] * 29_999)]}
    Capture.objects.filter(pk=crowded_capture.pk).update(n_joints=30_000, skeleton=skeleton)
    page = new_page("ann")
    page.goto(f"{live_server.url}/captures/{crowded_capture.pk}/")
    expect(page.get_by_test_id("too-many-joints")).to_contain_text("30,000 joints")
    last = crowded_capture.n_frames - 1
    page.keyboard.press("End")
    expect(page.get_by_test_id("hud-frame")).to_have_text(f"Frame {last} / {last}", timeout=PROMPT_MS)
    assert page.errors == []


def test_it_refuses_to_draw_what_the_service_is_set_to_refuse(live_server, new_page, crowded_capture, settings):
    settings.CUTROOM_MAX_JOINTS = 500
    page = new_page("ann")
    page.goto(f"{live_server.url}/captures/{crowded_capture.pk}/")
    expect(page.get_by_test_id("too-many-joints")).to_contain_text(
        "1,000 joints; the player draws at most 500")
    assert page.errors == []
