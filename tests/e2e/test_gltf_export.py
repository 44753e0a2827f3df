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
