"""Jobs whose process died are retried or failed within a minute, and jobs that run too
long are stopped: real workers, with the claim timeout and time limits of production
unless a test says otherwise."""

import contextlib
import os
import signal
import time

import psycopg
import pytest
from celery.exceptions import SoftTimeLimitExceeded
from django.contrib.auth import get_user_model
from django.core.files.uploadedfile import SimpleUploadedFile
from django.db import connection
from rest_framework.test import APIClient

from segmentation import services
from segmentation.models import Capture, DetectionRun, ProjectCutModel, Review
from segmentation.services import adaptation, captures, jobs
from tests.segmentation.base import synthetic_bvh
from tests.segmentation.integration.conftest import Workers, new_queue, sending_to, wait_for

pytestmark = pytest.mark.integration


@pytest.fixture
def owner(transactional_db):
    alice = get_user_model().objects.create_user("alice", password="alice-password")
    services.do_create_project(alice, "Studio A")
    return alice


@pytest.fixture(scope="module")
def long_take():
    return synthetic_bvh(seed=7, duration=240.0)


@pytest.fixture
def production_workers(services_env, shared_media, tmp_path, transactional_db, settings):
    """Workers with the default claim timeout (this test process sweeps like the
    supervisor does: independently of the workers)."""
    pool = Workers(new_queue(), shared_media, tmp_path, claim_timeout=settings.CUTROOM_CLAIM_TIMEOUT)
    with sending_to(pool.queue):
        yield pool
    pool.stop_all()


def api(user):
    client = APIClient()
    client.force_authenticate(user)
    return client


def project_of(user):
    from segmentation.models import Project

    return Project.objects.get(memberships__user=user)


def sweeping_until(predicate, timeout):
    """Run the sweep every second (as `make up`'s supervisor does) until ``predicate``."""
    def swept():
        jobs.sweep()
        return predicate()
    return wait_for(swept, timeout=timeout, interval=1.0, what="the job to finish")


def test_it_retries_within_a_minute_a_run_whose_pool_process_died_during_detection(
    production_workers, owner, long_take
):
    worker = production_workers.start()
    client = api(owner)
    data = {"project": project_of(owner).pk, "file": SimpleUploadedFile("long.bvh", long_take)}
    capture_id = client.post("/api/captures/", data, format="multipart").json()["id"]
    run = wait_for(
        lambda: DetectionRun.objects.filter(capture_id=capture_id, status="processing").first(),
        timeout=120, interval=0.01, what="the default detection to start",
    )
    [child] = production_workers.children(worker)
    os.kill(child, signal.SIGKILL)
    killed = time.monotonic()

    sweeping_until(
        lambda: DetectionRun.objects.get(pk=run.pk).status in ("ready", "failed"), timeout=90
    )
    assert time.monotonic() - killed < 60
    assert DetectionRun.objects.get(pk=run.pk).status == "ready"


def test_it_recovers_promptly_the_capture_a_killed_worker_was_ingesting(
    production_workers, owner, long_take
):
    worker = production_workers.start()
    client = api(owner)
    data = {"project": project_of(owner).pk, "file": SimpleUploadedFile("long.bvh", long_take)}
    capture_id = client.post("/api/captures/", data, format="multipart").json()["id"]
    wait_for(lambda: Capture.objects.get(pk=capture_id).status == "processing",
             interval=0.01, what="ingest to start")
    production_workers.kill(worker)
    killed = time.monotonic()
    production_workers.start()

    sweeping_until(lambda: Capture.objects.get(pk=capture_id).status in ("ready", "failed"),
                   timeout=90)
    assert time.monotonic() - killed < 60
    assert Capture.objects.get(pk=capture_id).status == "ready"


def start_slow_run(owner, long_take):
    """Upload the long take, wait for its ingest and default run, then start a run that
    takes seconds (ppca at a fine step); its id."""
    client = api(owner)
    capture_id = upload_and_detect(client, project_of(owner), "long.bvh", long_take)
    r = client.post(f"/api/captures/{capture_id}/runs/",
                    {"method": "ppca", "params": {"step_s": 0.04}}, format="json")
    assert r.status_code == 202, r.json()
    return r.json()["id"]


def test_it_stops_a_detection_run_at_its_time_limit_and_says_why(
    production_workers, owner, long_take
):
    production_workers.env["CUTROOM_DETECT_TIME_LIMIT"] = "1"
    production_workers.start()
    run_id = start_slow_run(owner, long_take)

    wait_for(lambda: DetectionRun.objects.get(pk=run_id).status == "failed",
             timeout=120, what="the run to be stopped")
    error = DetectionRun.objects.get(pk=run_id).error
    assert "took too long and was stopped" in error
    assert "detection 1 s, CUTROOM_DETECT_TIME_LIMIT" in error


def test_it_fails_at_once_a_run_killed_at_its_hard_time_limit(production_workers, owner, long_take):
    """A job that does not stop at its soft limit (as in native code that never returns
    to Python: here its pool process is stopped with SIGSTOP, so the soft limit's signal
    is never handled) has its process killed at the hard limit. The same input would run
    as long again, so the run fails at once, naming the limit, and is not retried."""
    production_workers.env.update(CUTROOM_DETECT_TIME_LIMIT="1", CUTROOM_TIME_LIMIT_GRACE="2")
    worker = production_workers.start()
    run_id = start_slow_run(owner, long_take)
    wait_for(lambda: DetectionRun.objects.get(pk=run_id).status == "processing",
             interval=0.01, what="the run to start")
    [child] = production_workers.children(worker)
    os.kill(child, signal.SIGSTOP)
    stopped = time.monotonic()

    sweeping_until(lambda: DetectionRun.objects.get(pk=run_id).status != "processing",
                   timeout=45)
    assert time.monotonic() - stopped < 15
    run = DetectionRun.objects.get(pk=run_id)
    assert run.status == "failed" and run.attempts == 1
    assert run.error.startswith("Detection stopped after its time limit of 1 s "
                                "(CUTROOM_DETECT_TIME_LIMIT)"), run.error
    assert run.finished_at is not None
    assert "Hard time limit" in worker.log.read_text()
    time.sleep(2)  # the message given back or acknowledged: either way nothing runs it again
    jobs.sweep()
    assert DetectionRun.objects.get(pk=run_id).attempts == 1


def upload_and_detect(client, project, name, content):
    data = {"project": project.pk, "file": SimpleUploadedFile(name, content)}
    capture_id = client.post("/api/captures/", data, format="multipart").json()["id"]
    wait_for(lambda: Capture.objects.get(pk=capture_id).status == "ready"
             and not DetectionRun.objects.filter(capture_id=capture_id,
                                                 status__in=("queued", "processing")).exists(),
             timeout=120, what=f"ingest and detection of {name}")
    return capture_id


def submit_review(client, capture_id):
    """Review the capture keeping its candidates, and submit (which asks for a training)."""
    review = client.post(f"/api/captures/{capture_id}/review/").json()
    r = client.post(f"/api/captures/{capture_id}/review/submit/", {"version": review["version"]},
                    format="json")
    assert r.status_code == 200, r.json()


def retrains_done(worker):
    return sum("segmentation.tasks.retrain[" in line and "succeeded" in line
               for line in worker.log.read_text().splitlines())


def test_it_fails_at_once_a_training_killed_at_its_hard_time_limit_and_trains_what_waited(
    production_workers, owner, long_take, settings
):
    """As for a run: a training that does not stop at its soft limit (its pool process
    stopped with SIGSTOP) is killed at the hard one and fails at once, naming the limit,
    and is not retried. The training asked for while it ran, whose message the other
    worker dropped (not its turn), is sent again when it fails."""
    settings.CUTROOM_RETRAIN_DELAY = 0
    production_workers.env.update(CUTROOM_RETRAIN_TIME_LIMIT="2", CUTROOM_TIME_LIMIT_GRACE="2")
    workers = [production_workers.start(), production_workers.start()]
    client, project = api(owner), project_of(owner)
    first = upload_and_detect(client, project, "long.bvh", long_take)
    second = upload_and_detect(client, project, "short.bvh", synthetic_bvh(seed=8, duration=40.0))
    submit_review(client, first)
    training = wait_for(lambda: ProjectCutModel.objects.filter(status="processing").first(),
                        timeout=30, interval=0.01, what="the training to start")
    children = {child: worker for worker in workers for child in production_workers.children(worker)}
    for child in children:
        os.kill(child, signal.SIGSTOP)
    stopped = time.monotonic()
    holder = wait_for(lambda: next((w for w in workers if training.claim_token in w.log.read_text()),
                                   None), timeout=5, what="the worker of the training")
    [other] = [w for w in workers if w is not holder]
    for child, worker in children.items():
        if worker is other:
            os.kill(child, signal.SIGCONT)
    assert ProjectCutModel.objects.get(pk=training.pk).status == "processing"
    before = retrains_done(other)
    submit_review(client, second)  # while the training runs: the next one waits for it
    waiting = ProjectCutModel.objects.get(project=project, status="queued")
    wait_for(lambda: retrains_done(other) > before, timeout=10, what="the other worker to drop it")

    sweeping_until(
        lambda: ProjectCutModel.objects.get(pk=training.pk).status != "processing", timeout=45)
    assert time.monotonic() - stopped < 15
    failed = ProjectCutModel.objects.get(pk=training.pk)
    assert (failed.status, failed.attempts, failed.version) == ("failed", 1, None)
    assert failed.error.startswith("Training stopped after its time limit of 2 s "
                                   "(CUTROOM_RETRAIN_TIME_LIMIT)"), failed.error
    assert failed.finished_at is not None
    assert "Hard time limit" in holder.log.read_text()
    rows = client.get(f"/api/projects/{project.pk}/cut-models/").json()
    assert failed.error in [row["error"] for row in rows]

    wait_for(lambda: ProjectCutModel.objects.get(pk=waiting.pk).status in ("ready", "failed"),
             timeout=30, what="the training that waited")
    trained = ProjectCutModel.objects.get(pk=waiting.pk)
    assert (trained.status, trained.version, trained.n_takes) == ("ready", 1, 2), trained.error
    assert trained.claimed_at >= failed.finished_at
    jobs.sweep()
    assert ProjectCutModel.objects.get(pk=training.pk).attempts == 1


def test_it_stops_a_training_at_its_soft_time_limit_and_says_why(
    production_workers, owner, long_take, settings
):
    """A training still running at its soft limit stops and fails naming the limit (not as
    an internal error). Its pool process is stopped (SIGSTOP) past the limit and then
    continued, so the limit's signal lands during the training however fast it is."""
    settings.CUTROOM_RETRAIN_DELAY = 0
    production_workers.env["CUTROOM_RETRAIN_TIME_LIMIT"] = "1"
    worker = production_workers.start()
    client, project = api(owner), project_of(owner)
    submit_review(client, upload_and_detect(client, project, "long.bvh", long_take))
    training = wait_for(lambda: ProjectCutModel.objects.filter(status="processing").first(),
                        timeout=30, interval=0.01, what="the training to start")
    [child] = production_workers.children(worker)
    os.kill(child, signal.SIGSTOP)
    time.sleep(2)
    os.kill(child, signal.SIGCONT)

    wait_for(lambda: ProjectCutModel.objects.get(pk=training.pk).status != "processing",
             timeout=20, what="the training to stop")
    failed = ProjectCutModel.objects.get(pk=training.pk)
    assert (failed.status, failed.version) == ("failed", None)
    assert failed.error.startswith("Training took too long and was stopped (time limit 1 s, "
                                   "CUTROOM_RETRAIN_TIME_LIMIT)"), failed.error


@contextlib.contextmanager
def soft_limit_after(seconds):
    """Raise SoftTimeLimitExceeded in this thread after ``seconds``, from a signal handler,
    as a worker's pool process does at a task's soft time limit: the exception lands
    wherever the job is, a database call included."""
    def reached(signum, frame):
        raise SoftTimeLimitExceeded()

    previous = signal.signal(signal.SIGALRM, reached)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


@contextlib.contextmanager
def table_locked(model):
    """Hold an exclusive lock on ``model``'s table from another connection, so a query on
    it waits until the block ends."""
    db = connection.settings_dict
    with psycopg.connect(host=db["HOST"] or "127.0.0.1", port=db["PORT"] or 5432,
                         user=db["USER"], dbname=db["NAME"], password=db["PASSWORD"]) as other:
        other.execute(f'LOCK TABLE "{model._meta.db_table}" IN ACCESS EXCLUSIVE MODE')
        yield
        other.rollback()


def test_a_training_whose_soft_limit_lands_inside_a_query_still_fails_naming_the_limit(
    services_env, owner
):
    """The soft limit's exception interrupts the query the training waits on, leaving that
    connection in the middle of a command; the failure is still written (on a connection
    that works) instead of the row staying "processing"."""
    job = ProjectCutModel.objects.create(project=project_of(owner), status="processing",
                                         claim_token="token")
    with table_locked(Review), soft_limit_after(0.5):
        adaptation.train_project_model(job)

    failed = ProjectCutModel.objects.get(pk=job.pk)
    assert (failed.status, failed.version) == ("failed", None)
    assert failed.error.startswith("Training took too long and was stopped"), failed.error


def test_a_detection_whose_soft_limit_lands_inside_a_query_still_fails_naming_the_limit(
    services_env, owner
):
    capture = Capture.objects.create(project=project_of(owner), name="take.bvh",
                                     status="ready", fps=120, n_frames=1200)
    run = DetectionRun.objects.create(capture=capture, method="default", status="processing",
                                      claim_token="token")
    with table_locked(Capture), soft_limit_after(0.5):
        jobs.guard(captures.DETECT, run, work=lambda run: list(Capture.objects.all()))

    failed = DetectionRun.objects.get(pk=run.pk)
    assert failed.status == "failed"
    assert "took too long and was stopped" in failed.error, failed.error
