"""FBX uploads through real workers: a convert worker (Blender) on its own queue, then the usual
ingest and detection on another; Blender crashing or hanging costs one capture, not the worker."""

import os
import signal
import subprocess
import threading

import pytest
from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile
from django.db import transaction
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture, DetectionRun
from tests.fbx.files import shared_fbx
from tests.segmentation.integration.conftest import Workers, new_queue, wait_for
from tests.segmentation.test_command_up import up_script

pytestmark = pytest.mark.integration


@pytest.fixture
def owner(transactional_db):
    alice = get_user_model().objects.create_user("alice", password="alice-password")
    services.do_create_project(alice, "Studio A")
    return alice


@pytest.fixture
def fbx_workers(workers, shared_media, tmp_path, settings):
    """An ingest worker on the test's queue and a convert worker on a convert queue of its own
    (``start_convert(**env)`` starts one, with extra environment, as ``make up`` starts it:
    its slots, its recycling)."""
    convert_queue = new_queue() + "-convert"
    settings.CUTROOM_CONVERT_QUEUE = convert_queue
    workers.env["CUTROOM_CONVERT_QUEUE"] = convert_queue
    workers.start()
    converters = Workers(convert_queue, shared_media, tmp_path, claim_timeout=300)
    converters.env.update(CUTROOM_CONVERT_WORKER="1", CUTROOM_CONVERT_QUEUE=convert_queue)

    def start_convert(**env):
        converters.env.update(env)
        options = up_script().convert_options(converters.env)
        return converters.start(f"convert-{len(converters.procs)}", options)

    yield start_convert, converters
    converters.stop_all()


def upload(owner, path, name=None):
    client = APIClient()
    client.force_authenticate(owner)
    data = {"project": owner.memberships.get().project_id,
            "file": SimpleUploadedFile(name or path.name, path.read_bytes())}
    response = client.post("/api/captures/", data, format="multipart")
    assert response.status_code == 201, response.content
    return response.json()["id"]


def settled(capture_id, timeout=120):
    wait_for(lambda: Capture.objects.get(pk=capture_id).status in ("ready", "failed"),
             timeout=timeout, what="the capture to be converted and ingested")
    return Capture.objects.get(pk=capture_id)


def blender_pids(worker):
    """Blender processes started by this worker's pool process."""
    out = subprocess.run(["pgrep", "-f", "_blender_fbx.py"], capture_output=True, text=True)
    pool = set(Workers.children(None, worker))
    return [int(p) for p in out.stdout.split() if _parent(int(p)) in pool]


def blenders_ready(worker):
    """Once every pool process (slot) of the convert worker has loaded its Blender, their pids."""
    slots = len(Workers.children(None, worker))
    wait_for(lambda: worker.log.read_text().count("Blender ready in") >= slots,
             what="Blender to start in every slot")
    blender = blender_pids(worker)
    assert len(blender) == slots
    return blender


def _parent(pid):
    try:
        with open(f"/proc/{pid}/stat") as stat:
            return int(stat.read().rsplit(")", 1)[1].split()[1])
    except OSError:
        return None


def test_it_converts_then_ingests_and_detects_an_fbx_upload(fbx_workers, owner):
    start_convert, _ = fbx_workers
    start_convert()
    capture = settled(upload(owner, shared_fbx("samba_dancing.fbx")))
    assert capture.status == "ready", capture.error
    assert (capture.format, capture.n_frames, capture.fps) == ("fbx", 595, 30.0)
    wait_for(lambda: DetectionRun.objects.filter(capture=capture, status="ready").exists(),
             what="detection")


def test_it_makes_a_capture_per_animation(fbx_workers, owner, made_fbx):
    start_convert, _ = fbx_workers
    worker = start_convert()
    blender = blenders_ready(worker)
    first = settled(upload(owner, made_fbx / "two_armatures.fbx"))
    assert first.status == "ready", first.error
    other = Capture.objects.get(source=first)
    assert settled(other.pk).status == "ready"
    assert sorted([first.name, other.name]) == ["two_armatures.fbx#Breakdance|Scene",
                                                "two_armatures.fbx#Flair|Scene"]
    # A Blender loaded as the worker started read the file: none started for it.
    assert blender_pids(worker) == blender


def test_one_kill_of_blender_does_not_fail_a_good_fbx(fbx_workers, owner):
    """Issue 48, item 11: one outside kill of the Blender child failed a good FBX for good;
    the read is tried again in a fresh Blender."""
    start_convert, _ = fbx_workers
    worker = start_convert()
    blenders_ready(worker)
    capture_id = upload(owner, shared_fbx("13_29_blender.fbx"))
    wait_for(lambda: Capture.objects.get(pk=capture_id).status == "processing", interval=0.01,
             what="conversion to start")
    # Every slot's Blender, the one reading the file among them (the others start afresh
    # on their next file).
    killed = blender_pids(worker)
    for pid in killed:
        os.kill(pid, signal.SIGKILL)
    converted = settled(capture_id)
    assert converted.status == "ready", converted.error
    assert not set(blender_pids(worker)) & set(killed)
    assert settled(upload(owner, shared_fbx("flair.fbx"))).status == "ready"
    assert worker.poll() is None


def test_a_blender_past_its_time_limit_fails_that_capture_only(fbx_workers, owner):
    start_convert, _ = fbx_workers
    # Reading 13_29 takes Blender a second or more: 0.3 s is "hanging" for this test.
    worker = start_convert(MOTIONLIB_BLENDER_TIMEOUT="0.3")
    slow = settled(upload(owner, shared_fbx("13_29_blender.fbx")))
    assert slow.status == "failed"
    assert "Blender did not finish reading the FBX within 0.3 s and was stopped" in slow.error
    # The worker goes on with the next file in a fresh Blender. (Under this test's 0.3 s
    # limit a real file may itself count as hanging when the machine is busy: either way it
    # is settled, not stuck.)
    after = settled(upload(owner, shared_fbx("flair.fbx")))
    assert after.status == "ready" or "within 0.3 s and was stopped" in after.error
    assert worker.poll() is None


@pytest.fixture
def hanging_upload(owner):
    """Upload an FBX whose stored original then hangs Blender: a named pipe that gives the
    header check the file's first bytes, then leaves Blender's read waiting for a writer.
    Yields the upload function; lets Blender go at the end."""
    pipes = []

    def upload_hanging(path):
        head = path.read_bytes()[:64]
        project = owner.memberships.get().project
        with transaction.atomic():  # the job is sent on commit: after the swap
            capture, _ = services.do_upload_capture(
                project, owner, SimpleUploadedFile("hangs.fbx", path.read_bytes()))
            stored = capture.original.path
            os.remove(stored)
            os.mkfifo(stored)
        pipes.append(stored)
        threading.Thread(target=_feed, args=(stored, head), daemon=True).start()
        return capture.pk

    yield upload_hanging
    for pipe in pipes:
        try:  # a writer that closes at once: Blender reads the end of the file
            os.close(os.open(pipe, os.O_WRONLY | os.O_NONBLOCK))
        except OSError:
            pass  # nobody reading it any more


def _feed(pipe, head):
    with open(pipe, "wb") as writer:
        writer.write(head)


def test_a_file_that_hangs_blender_holds_its_own_slot_only(fbx_workers, owner, hanging_upload):
    start_convert, _ = fbx_workers
    worker = start_convert()
    wait_for(lambda: "Blender ready in" in worker.log.read_text(), what="Blender to start")
    hung = hanging_upload(shared_fbx("flair.fbx"))
    wait_for(lambda: Capture.objects.get(pk=hung).status != "queued",
             what="the hanging conversion to start")
    assert Capture.objects.get(pk=hung).status == "processing", Capture.objects.get(pk=hung).error
    bob = get_user_model().objects.create_user("bob", password="bob-password")
    services.do_create_project(bob, "Studio B")
    other = settled(upload(bob, shared_fbx("flair.fbx")))
    assert other.status == "ready", other.error
    # Served while the hanging file still held its slot (MOTIONLIB_BLENDER_TIMEOUT, 300 s).
    assert Capture.objects.get(pk=hung).status == "processing"


def test_one_persons_hanging_files_never_hold_back_another_persons(fbx_workers, owner,
                                                                   hanging_upload):
    """Issue 48, item 5: two files of one annotator that hang Blender held both convert
    slots, and another user's small FBX waited 293 s. One person's conversions take one slot
    at most; the second waits for the first, and is sent when it ends."""
    start_convert, _ = fbx_workers
    worker = start_convert(CUTROOM_CONVERT_SLOTS="2")
    blenders_ready(worker)
    first = hanging_upload(shared_fbx("flair.fbx"))
    wait_for(lambda: Capture.objects.get(pk=first).status == "processing",
             what="the first hanging conversion to start")
    second = hanging_upload(shared_fbx("13_29_blender.fbx"))
    bob = get_user_model().objects.create_user("bob", password="bob-password")
    services.do_create_project(bob, "Studio B")
    other = settled(upload(bob, shared_fbx("flair.fbx")), timeout=90)
    assert other.status == "ready", other.error
    assert Capture.objects.get(pk=first).status == "processing"
    assert Capture.objects.get(pk=second).status == "queued"  # its turn comes after the first
    # The first file's Blender reads on and fails; the second is sent then, and starts.
    os.close(os.open(Capture.objects.get(pk=first).original.path, os.O_WRONLY | os.O_NONBLOCK))
    wait_for(lambda: Capture.objects.get(pk=first).status not in ("queued", "processing"),
             timeout=90, what="the first file to end")
    wait_for(lambda: Capture.objects.get(pk=second).status != "queued", timeout=60,
             what="the second file to be sent once the first ended")
