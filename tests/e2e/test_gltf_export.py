"""An FBX take's library segment exported as glTF binary loads in three.js's GLTFLoader in the
browser (the library's "▶ glTF" plays the service's .glb export as any glTF viewer would)."""

import pytest
from playwright.sync_api import expect

from tests.fbx.files import shared_fbx
from tests.segmentation.test_library import submit_review


@pytest.fixture
def fbx_segments(studio):
    """samba_dancing.fbx uploaded, converted by Blender, ingested, reviewed by ann."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services, tasks
    from segmentation.models import Capture, DetectionRun, LibrarySegment

    upload = SimpleUploadedFile("samba.fbx", shared_fbx("samba_dancing.fbx").read_bytes())
    capture, _ = services.do_upload_capture(studio["project"], studio["alice"], upload)
    tasks.convert(capture.pk)
    tasks.ingest(capture.pk)
    for run in DetectionRun.objects.filter(capture=capture, status="queued"):
        tasks.detect(run.pk)
    capture = Capture.objects.get(pk=capture.pk)
    assert capture.status == "ready", capture.error
    submit_review(capture, studio["ann"], [150, 300], ["walk", "squat", "kick"])
    return list(LibrarySegment.objects.order_by("start"))


def test_it_loads_a_segments_glb_export_with_threejs(live_server, new_page, fbx_segments,
                                                    screenshots):
    segment = fbx_segments[1]  # frames 150-300 at 30 fps
    page = new_page("ann")
    page.goto(f"{live_server.url}/library/")
    page.get_by_test_id(f"play-glb-{segment.pk}").click()
    preview = page.get_by_test_id("preview")
    expect(preview).to_have_attribute("data-playing", f"glb:{segment.pk}", timeout=90_000)
    # GLTFLoader parsed the file: the Mixamo rig's 65 joints move, for 150 frames at 30 fps.
    expect(preview).to_have_attribute("data-gltf-joints", "65")
    assert float(preview.get_attribute("data-gltf-duration")) == pytest.approx(149 / 30, abs=1e-3)
    expect(page.get_by_test_id("preview-caption")).to_contain_text("glTF · 65 joints · 4.97 s")
    expect(preview.locator("canvas")).to_be_visible()
    page.wait_for_timeout(500)  # a few frames of the clip
    page.screenshot(path=str(screenshots / "library-gltf.png"))
    assert page.errors == []


def test_it_shows_the_framed_skeleton_of_a_bvh_clips_glb(live_server, new_page, studio,
                                                       ingested_capture, screenshots):
    """A BVH clip's glTF is an armature without a mesh: the preview draws its skeleton,
    framed, a person's height in metres."""
    from segmentation.models import LibrarySegment

    submit_review(ingested_capture, studio["ann"], [1200, 2400], ["walk", "squat", "kick"])
    segment = LibrarySegment.objects.get(start=1200)
    page = new_page("ann")
    page.goto(f"{live_server.url}/library/")
    page.get_by_test_id(f"play-glb-{segment.pk}").click()
    preview = page.get_by_test_id("preview")
    expect(preview).to_have_attribute("data-playing", f"glb:{segment.pk}", timeout=90_000)
    expect(preview.locator("canvas")).to_be_visible()
    page.wait_for_timeout(500)
    drawn = preview.evaluate(DRAWN_BOX)
    assert drawn["pixels"] > 500, drawn
    # Framed: its height neither a speck nor cut off.
    assert 0.3 < drawn["bottom"] - drawn["top"] < 0.95, drawn
    assert 1.0 < float(preview.get_attribute("data-gltf-height")) < 2.0  # metres
    page.screenshot(path=str(screenshots / "library-gltf-bvh.png"))
    assert page.errors == []


# Where the preview's drawn pixels (not the background #161a21) lie: how many, and their box
# as shares of the canvas's width and height.
DRAWN_BOX = """(box) => {
  const canvas = box.querySelector("canvas");
  const copy = document.createElement("canvas");
  copy.width = canvas.width;
  copy.height = canvas.height;
  const context = copy.getContext("2d");
  context.drawImage(canvas, 0, 0);
  const data = context.getImageData(0, 0, canvas.width, canvas.height).data;
  let pixels = 0, left = canvas.width, right = -1, top = canvas.height, bottom = -1;
  for (let i = 0; i < data.length; i += 4) {
    const off = Math.abs(data[i] - 0x16) + Math.abs(data[i + 1] - 0x1a) + Math.abs(data[i + 2] - 0x21);
    if (off > 60) {
      pixels++;
      const x = (i / 4) % canvas.width, y = Math.floor(i / 4 / canvas.width);
      left = Math.min(left, x); right = Math.max(right, x);
      top = Math.min(top, y); bottom = Math.max(bottom, y);
    }
  }
  return { pixels, left: left / canvas.width, right: (right + 1) / canvas.width,
           top: top / canvas.height, bottom: (bottom + 1) / canvas.height };
}"""


@pytest.fixture
def walking_segment(studio):
    """The first 4 s of CMU 86_01 (AMC), in which the actor walks about 2 m: one segment."""
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation.models import LibrarySegment
    from tests.motionlib.conftest import cmu_file
    from tests.segmentation.base import ingested

    amc, asf = cmu_file("amc", "86_01.amc"), cmu_file("asf", "86.asf")
    capture = ingested(studio["project"], studio["alice"],
                       SimpleUploadedFile("86_01.amc", amc.read_bytes()),
                       asf=SimpleUploadedFile("86.asf", asf.read_bytes()))
    submit_review(capture, studio["ann"], [480], ["walk", None])
    return LibrarySegment.objects.get(capture=capture, start=0)


def test_the_preview_keeps_a_walking_clip_in_view_from_start_to_end(live_server, new_page,
                                                                    walking_segment, screenshots):
    """The camera frames the whole clip's motion, not its first pose: the walker stays on
    the canvas, whole, through a full loop of the clip."""
    page = new_page("ann")
    page.goto(f"{live_server.url}/library/")
    page.get_by_test_id(f"play-glb-{walking_segment.pk}").click()
    preview = page.get_by_test_id("preview")
    expect(preview).to_have_attribute("data-playing", f"glb:{walking_segment.pk}", timeout=90_000)
    duration = float(preview.get_attribute("data-gltf-duration"))
    assert duration == pytest.approx(4.0, abs=0.01)
    samples = []
    for _ in range(int(duration / 0.2) + 5):  # more than one loop
        samples.append(preview.evaluate(DRAWN_BOX))
        if len(samples) == 12:  # about half way through the walk
            page.screenshot(path=str(screenshots / "library-gltf-walk.png"))
        page.wait_for_timeout(200)
    cut = [s for s in samples if s["pixels"] < 300 or s["left"] <= 0.01 or s["right"] >= 0.99
           or s["top"] <= 0.01 or s["bottom"] >= 0.99]
    assert cut == [], f"{len(cut)} of {len(samples)} moments leave the view: {cut[:3]}"
    assert page.errors == []
