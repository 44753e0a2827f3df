"""Reference video in the browser (issue 49, item 1): a reviewer adds a real H.264 video of
a real CMU take through the dock's file dialog, aligns it by one event and nudges it by a
frame; it plays in sync with the take (the video element's time against the take's frame
plus the offset) while playing, after a seek on the ruler, after frame steps and at half
speed; the offset survives a reload; an annotator watches it without the controls; the
adjudication page plays it too. Bad files are refused in the dock, each with its message."""

from pathlib import Path

import pytest
from playwright.sync_api import expect

from tests.videofiles import make_video

TAKE_FPS = 120.0
VIDEO_FPS = 30
# While playing, the frame read on the page is the floor of the clock's position (up to a
# take frame behind it): half the samples are within a video frame of it...
PLAYING_TOLERANCE_S = 1 / VIDEO_FPS + 1 / TAKE_FPS
# ...and every one within what a stall of the page costs on a busy machine (software WebGL
# on two shared cores): the clock waits for the page, the video does not, and catches up
# by its rate or, past sync.ts's JUMP_S, a seek. A video off by its offset (0.47 s) or
# playing at the wrong rate is far outside both.
PLAYING_STALL_S = 0.2
# Paused, the video is put on the frame's exact time.
PAUSED_TOLERANCE_S = 0.002


@pytest.fixture
def real_take(studio, shared_data):
    """CMU take 06_02 (721 frames at 120 fps, 6.0 s), ingested as a worker would."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from tests.segmentation.base import ingested

    amc, asf = shared_data / "cmu" / "amc" / "06_02.amc", shared_data / "cmu" / "asf" / "06.asf"
    return ingested(studio["project"], studio["alice"], SimpleUploadedFile(amc.name, amc.read_bytes()),
                    asf=SimpleUploadedFile(asf.name, asf.read_bytes()))


def sample(page):
    """The video's time, the take's frame on the page and whether the video plays, read at
    one moment: in an animation frame, right after the page drew the take's frame in it
    (between two drawings the video runs on while the page still shows the last frame)."""
    return page.evaluate("""() => new Promise((resolve) => requestAnimationFrame(() => {
        const v = document.querySelector('[data-testid=reference-video]');
        const hud = document.querySelector('[data-testid=hud-frame]').textContent;
        resolve({time: v.currentTime, frame: Number(hud.match(/Frame (\\d+)/)[1]), playing: !v.paused,
                 rate: v.playbackRate});
    }))""")


def settled(page):
    """Wait until the video has finished seeking."""
    page.wait_for_function("() => { const v = document.querySelector('[data-testid=reference-video]');"
                           " return v.readyState >= 2 && !v.seeking; }")


def assert_in_sync(page, offset, tolerance):
    now = sample(page)
    expected = now["frame"] / TAKE_FPS + offset
    assert abs(now["time"] - expected) <= tolerance, (now, expected)
    return now


def assert_playing_in_sync(page, offset, count):
    """``count`` samples 60 ms apart while playing: each within PLAYING_STALL_S of the take's
    frame plus the offset, and half of them within PLAYING_TOLERANCE_S."""
    samples = []
    for _ in range(count):
        now = assert_in_sync(page, offset, PLAYING_STALL_S)
        assert now["playing"], now
        samples.append(now)
        page.wait_for_timeout(60)
    errors = sorted(abs(s["time"] - s["frame"] / TAKE_FPS - offset) for s in samples)
    assert errors[len(errors) // 2] <= PLAYING_TOLERANCE_S, errors
    return samples


def wait_offset_saved(page, value):
    expect(page.get_by_test_id("video-dock")).to_have_attribute("data-saved-offset", str(value))


def ruler_click(page, frame, n_frames):
    box = page.locator("[data-testid=timeline] canvas").bounding_box()
    page.mouse.click(box["x"] + (frame + 0.5) / n_frames * box["width"], box["y"] + 12)


def test_a_reference_video_plays_in_sync_with_the_take(live_server, new_page, studio, real_take, screenshots):
    from segmentation.models import ReferenceVideo

    n = real_take.n_frames
    video_file = make_video("h264", seconds=round(n / TAKE_FPS, 3), fps=VIDEO_FPS, size="320x240")
    page = new_page("rachel")
    page.goto(f"{live_server.url}/captures/{real_take.pk}/")
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    dock = page.get_by_test_id("video-dock")
    expect(dock).to_contain_text("No reference video yet")

    # Added through the file dialog; the server read its codec, rate and length.
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id("video-add").click()
    chooser.value.set_files(str(video_file))
    expect(page.get_by_test_id("video-facts")).to_contain_text("H264 · 30 fps · ")
    stored = ReferenceVideo.objects.get(capture=real_take)
    # As long as the take, to the next whole video frame.
    assert 0 <= stored.duration - n / TAKE_FPS < 1 / VIDEO_FPS
    expect(page.get_by_test_id("video-facts")).to_contain_text(f"{stored.duration:.2f} s · 320×240")
    assert stored.file.read() == video_file.read_bytes()
    settled(page)

    # Aligned by one event: take frame 240 is at 2.5 s in the video; then one video frame back.
    page.get_by_test_id("align-frame").fill("240")
    page.get_by_test_id("align-time").fill("2.5")
    page.get_by_test_id("align").click()
    wait_offset_saved(page, 0.5)
    page.get_by_test_id("video-nudge-minus-1").click()
    offset = round(0.5 - 1 / VIDEO_FPS, 6)
    wait_offset_saved(page, offset)
    expect(page.get_by_test_id("video-offset")).to_have_text("+0.467 s")
    stored.refresh_from_db()
    assert stored.offset_s == pytest.approx(offset) and stored.offset_set_by.username == "rachel"

    # Paused on frame 0 the video shows 0.467 s; a step shows the next take frame's time.
    settled(page)
    assert_in_sync(page, offset, PAUSED_TOLERANCE_S)
    for _ in range(3):
        page.keyboard.press("ArrowRight")
    settled(page)
    assert assert_in_sync(page, offset, PAUSED_TOLERANCE_S)["frame"] == 3

    # Playing: sampled in twenty animation frames while the take plays, the video keeps to
    # the take's frame.
    page.keyboard.press("Space")
    frames = [now["frame"] for now in assert_playing_in_sync(page, offset, 20)]
    assert frames == sorted(frames) and frames[-1] - frames[0] > 120, frames

    # A seek on the ruler while playing: the video follows to the new place.
    ruler_click(page, 120, n)
    page.wait_for_timeout(300)
    assert 120 <= assert_playing_in_sync(page, offset, 8)[0]["frame"] < 300

    # Paused after it, then stepped back ten frames: exact again.
    page.keyboard.press("Space")
    expect(page.get_by_test_id("hud-state")).to_contain_text("paused")
    settled(page)
    paused = assert_in_sync(page, offset, PAUSED_TOLERANCE_S)
    assert not paused["playing"]
    page.keyboard.press(",")
    settled(page)
    assert assert_in_sync(page, offset, PAUSED_TOLERANCE_S)["frame"] == paused["frame"] - 10
    page.screenshot(path=str(screenshots / "reference-video.png"))

    # At half speed the video plays at half rate and stays on the take.
    page.get_by_test_id("speed").select_option("0.5")
    page.keyboard.press("Space")
    page.wait_for_timeout(300)
    rates = sorted(now["rate"] for now in assert_playing_in_sync(page, offset, 8))
    assert rates[len(rates) // 2] == pytest.approx(0.5, abs=0.05), rates
    page.keyboard.press("Space")

    # At frame 0 the video is already 0.467 s in: nothing to say about it.
    page.keyboard.press("Home")
    settled(page)
    expect(page.get_by_test_id("video-outside")).to_be_hidden()
    assert page.evaluate("document.querySelector('[data-testid=reference-video]').currentTime") == pytest.approx(offset, abs=0.002)

    # The offset is the server's: a reload shows it, and the video follows it.
    page.reload()
    page.wait_for_selector("[data-testid=frames-loading][data-done]", state="attached")
    expect(page.get_by_test_id("video-offset")).to_have_text("+0.467 s")
    ruler_click(page, 360, n)
    settled(page)
    assert_in_sync(page, offset, PAUSED_TOLERANCE_S)
    assert page.errors == []

    # An annotator watches the same video in sync but cannot add, nudge or align.
    ann = new_page("ann")
    ann.goto(f"{live_server.url}/captures/{real_take.pk}/")
    expect(ann.get_by_test_id("video-offset")).to_have_text("+0.467 s")
    expect(ann.get_by_test_id("video-add")).to_have_count(0)
    expect(ann.get_by_test_id("video-nudge-plus-1")).to_have_count(0)
    expect(ann.get_by_test_id("video-align")).to_have_count(0)
    settled(ann)
    for _ in range(5):
        ann.keyboard.press("ArrowRight")
    settled(ann)
    assert assert_in_sync(ann, offset, PAUSED_TOLERANCE_S)["frame"] == 5

    # The adjudication page plays it on its own clock too.
    adj = new_page("rachel")
    adj.goto(f"{live_server.url}/captures/{real_take.pk}/adjudicate/")
    expect(adj.get_by_test_id("video-offset")).to_have_text("+0.467 s")
    settled(adj)
    adj.keyboard.press("End")
    settled(adj)
    end = adj.evaluate("document.querySelector('[data-testid=reference-video]').currentTime")
    assert end == pytest.approx(min((n - 1) / TAKE_FPS + offset, stored.duration), abs=0.002)
    expect(adj.get_by_test_id("video-outside")).to_have_text("The video has ended")
    adj.keyboard.press("Home")
    for _ in range(12):
        adj.keyboard.press("ArrowRight")
    settled(adj)
    time = adj.evaluate("document.querySelector('[data-testid=reference-video]').currentTime")
    assert time == pytest.approx(12 / TAKE_FPS + offset, abs=PAUSED_TOLERANCE_S)
    assert ann.errors == [] and adj.errors == []


def upload_in_dock(page, path):
    with page.expect_file_chooser() as chooser:
        page.get_by_test_id("video-add").click()
    chooser.value.set_files(str(path))


def test_the_dock_names_each_file_it_refuses_and_why(live_server, new_page, studio, real_take, tmp_path, settings):
    from segmentation.models import ReferenceVideo

    page = new_page("alice")
    page.goto(f"{live_server.url}/captures/{real_take.pk}/")
    status = page.get_by_test_id("video-status")
    notes = tmp_path / "notes.mp4"
    notes.write_text("take 3: the clap is at 00:00:02:10\n")
    upload_in_dock(page, notes)
    expect(status).to_contain_text("'notes.mp4' is not a video browsers play")
    upload_in_dock(page, make_video("hevc"))
    expect(status).to_contain_text("is HEVC (H.265) video in MP4, which browsers do not play")
    upload_in_dock(page, make_video("prores"))
    expect(status).to_contain_text("is a QuickTime .mov (often ProRes)")
    # Over the size limit: the server refuses it (413) and the dock says so...
    settings.CUTROOM_MAX_VIDEO_MB = 0
    upload_in_dock(page, make_video("h264"))
    expect(status).to_contain_text("the limit for a video is 0 MB (CUTROOM_MAX_VIDEO_MB)")
    # ...and once the page knows the limit it refuses before sending.
    page.reload()
    upload_in_dock(page, make_video("vp9"))
    expect(status).to_contain_text(f"{Path(make_video('vp9')).name} is ")
    expect(status).to_contain_text(" MB; the limit for a video is 0 MB.")
    assert not ReferenceVideo.objects.exists()
    assert page.errors == []
