"""Captures and detection runs: upload, ingest, detect (the jobs' lifecycle, from claim to
close, is ``services.jobs``)."""

import hashlib
import logging
import os
import re
import uuid

import numpy as np
from django.conf import settings
from django.db import IntegrityError, transaction
from django.utils import timezone

import motionlib
from motionlib.errors import shorten
from motionlib.segmenters import ParamError, get_segmenter, list_segmenters
from segmentation.errors import CutroomError, NotReady, ReviewStarted, UploadError, UploadTooLarge
from segmentation.files import cleanup, storage
from segmentation.files.storage import read_take
from segmentation.models import Capture, DetectionRun, Project
from segmentation.services import adaptation, jobs, quotas
from segmentation.services.jobs import Kind, enqueue, register
from segmentation.services.reviews import do_take_in_candidates

log = logging.getLogger(__name__)

FORMATS = {".bvh": "bvh", ".amc": "amc", ".fbx": "fbx", ".c3d": "c3d", ".tsv": "tsv",
           ".csv": "csv"}
# Stored file names keep word characters only and stay well under the 255 bytes a file
# system allows per name (the capture's name keeps what the user uploaded; Django has cut
# it to 255 characters, which may be up to 1,020 bytes).
MAX_STORED_STEM_BYTES = 100


def default_method():
    """The registry's recommended method: ``default`` once registered, else ``bone_angle``."""
    names = {cls.name for cls in list_segmenters()}
    return "default" if "default" in names else "bone_angle"


def validate_method(method, params):
    """(method name, validated params); ParamError names the bad method or parameter."""
    method = method or default_method()
    return method, get_segmenter(method).validate_params(params or {})


def max_upload_bytes():
    return settings.CUTROOM_MAX_UPLOAD_MB * 1024 * 1024


def check_upload(upload, asf=None):
    """The capture format of an upload; UploadError says what is wrong with it."""
    extension = os.path.splitext(upload.name)[1].lower()
    if extension not in FORMATS:
        raise UploadError(
            f"file: {shorten(upload.name)} has extension {shorten(extension or '(none)')}; "
            "upload a .bvh or binary .fbx file, an .amc file with its .asf skeleton, or "
            "points: .c3d markers, a Qualisys .tsv export or a joint-position .csv"
        )
    for field, item in (("file", upload), ("asf", asf)):
        if item is None:
            continue
        if item.size == 0:
            raise UploadError(f"{field}: {item.name!r} is empty (0 bytes)")
        if item.size > max_upload_bytes():
            raise UploadTooLarge(
                f"{field}: {item.name!r} is {item.size / 2**20:.1f} MB; the limit is "
                f"{settings.CUTROOM_MAX_UPLOAD_MB} MB (CUTROOM_MAX_UPLOAD_MB)"
            )
    if FORMATS[extension] == "amc" and asf is None:
        raise UploadError(f"asf: {upload.name!r} is an AMC file; upload its .asf skeleton with it")
    if asf is not None and os.path.splitext(asf.name)[1].lower() != ".asf":
        raise UploadError(f"asf: {asf.name!r} is not an .asf file")
    return FORMATS[extension]


def checksum(upload, asf=None):
    """SHA-256 over the original (and its ASF): equal takes give equal checksums."""
    digest = hashlib.sha256()
    for item in (upload, asf):
        if item is not None:
            for chunk in item.chunks():
                digest.update(chunk)
    return digest.hexdigest()


def do_upload_capture(project, user, upload, asf=None, rate_limited=False):
    """Store an upload unchanged and queue its ingest.

    Returns (capture, created); an identical upload to the same project returns the
    existing capture with ``created=False``. People uploading through the API are
    ``rate_limited`` (CUTROOM_UPLOADS_PER_HOUR); imports by command are not. The quotas
    are counted and the capture inserted under the project's and the user's row locks,
    so simultaneous uploads cannot pass them together.
    """
    fmt = check_upload(upload, asf)
    if rate_limited:
        quotas.check_upload_rate(user)  # before the duplicate check, which may requeue
    digest = checksum(upload, asf)
    existing = Capture.objects.filter(project=project, checksum=digest).first()
    if existing:
        # Uploading a failed take again is the natural way to ask for another try (if a
        # concurrent retry queued it already, that is just as good).
        if existing.status == "failed" and _requeue_failed(existing):
            existing.refresh_from_db()
        return existing, False
    size = upload.size + (asf.size if asf is not None else 0)
    # Before storing the file, without locks: most refusals need not write anything.
    quotas.check_storage(project, user, size)
    capture = Capture(project=project, uploaded_by=user, name=upload.name, format=fmt,
                      rate_limited=rate_limited)
    capture.checksum, capture.stored_bytes = digest, size
    capture.original.save(stored_name(upload.name), upload, save=False)
    if asf is not None:
        capture.asf.save(stored_name(asf.name), asf, save=False)
    try:
        with transaction.atomic():
            quotas.lock(project, user)
            _check_quotas(project, user, size, rate_limited)
            capture.save()
            enqueue(capture.first_job(), capture.pk)
    except IntegrityError:
        # The same file arrived twice at once; the other request stored it.
        _delete_files(capture)
        return Capture.objects.get(project=project, checksum=digest), False
    except CutroomError:
        _delete_files(capture)
        raise
    return capture, True


def _check_quotas(project, user, size, rate_limited):
    if rate_limited:
        quotas.check_upload_rate(user)
    quotas.check_storage(project, user, size)


def _delete_files(capture):
    """Remove the files of a capture that was not saved (refused, or a duplicate)."""
    for field in (capture.original, capture.asf):
        if field.name:
            field.storage.delete(field.name)


def stored_name(name):
    """A file name for storing an upload: its stem's word characters (cut to
    MAX_STORED_STEM_BYTES of UTF-8, or ``capture`` when none are left) and its extension."""
    stem, extension = os.path.splitext(os.path.basename(name))
    stem = re.sub(r"[^\w-]", "", stem.replace(" ", "_"))
    while len(stem.encode()) > MAX_STORED_STEM_BYTES:
        stem = stem[:-1]
    return f"{stem or 'capture'}{extension.lower()}"


def do_retry_capture(capture):
    """Queue the ingest of a failed capture again, from its stored original.

    For a failure that was not the file's fault (a worker lost too often, storage down,
    a parser bug since fixed); the error of the last try is cleared when it is queued.
    """
    if not _requeue_failed(capture):
        capture.refresh_from_db(fields=["status"])
        raise NotReady(
            f"capture {capture.pk} is {capture.status}; only a failed capture can be retried"
        )


def _requeue_failed(capture):
    """Queue a failed capture's ingest again; False if it was not failed (any more)."""
    with transaction.atomic():
        if not Capture.objects.requeue_failed(capture.pk):
            return False
        enqueue(capture.first_job(), capture.pk)
    return True


def do_start_run(capture, user, method, params):
    """Queue a detection run on a ready capture; ParamError names a bad parameter."""
    if capture.status != "ready":
        raise NotReady(f"capture {capture.pk} is {capture.status}; detection needs a ready capture")
    method, params = validate_method(method, params)
    with transaction.atomic():
        quotas.check_active_runs(capture.project, user)
        run = DetectionRun.objects.create(
            capture=capture, method=method, params=params, created_by=user
        )
        enqueue("detect", run.pk)
    return run


def ingest_capture(capture):
    """Parse a claimed capture, store its metadata and positions, start default detection.

    A bad file marks the capture failed with motionlib's message (file, line, value).
    """
    jobs.guard(INGEST, capture)


def _ingest(capture):
    take = read_take(capture)
    # Detection below, in this process, reuses the world positions (they are read-only).
    take.positions = motionlib.forward_kinematics(take)
    take.positions.flags.writeable = False
    positions = np.asarray(take.positions, dtype="<f4")
    height = float(motionlib.skeleton_height(take))
    storage.save_npy(capture.positions, "positions.npy", positions)
    run = None
    with transaction.atomic():
        if capture.finish(**_metadata(take, height), positions=capture.positions.name):
            run = _start_default_run(capture)
        else:  # deleted meanwhile, or taken over: nothing names the file just written
            cleanup.forget(capture.positions)
    if run is not None:
        _detect_here(run, take)


def _detect_here(run, take):
    """Run the default detection now, on the take this worker has just parsed (saves
    reading the file again and a trip through the queue), unless a worker claimed the run
    first. The queued message stays as the fallback: if this process dies the claim goes
    stale and the sweep requeues the run; otherwise its delivery finds the run claimed."""
    jobs.run(DETECT, run.pk, uuid.uuid4().hex, work=lambda run: _detect(run, take))


def _metadata(take, height):
    skeleton = {
        "joints": list(take.skeleton.names),
        "parents": [int(p) for p in take.skeleton.parents],
        "height": height,
        "up": "y",
    }
    if take.skeleton.point_set:
        # Points, not joints: parents are the links of a known marker set (-1: none).
        skeleton.update(kind="points", marker_set=take.marker_set, unit=take.unit,
                        first_number=int(take.first_number))
    return {
        "format": take.format,
        "fps": float(take.fps),
        "n_frames": int(take.n_frames),
        "n_joints": len(take.skeleton.names),
        "rest_pose_frame": take.rest_pose_frame,
        "skeleton": skeleton,
    }


def _start_default_run(capture):
    project = capture.project
    try:
        method, params = validate_method(project.default_method, project.default_params)
    except ParamError as exc:
        # Keep the capture usable; the failed run says why the project's defaults are wrong.
        DetectionRun.objects.create(
            capture=capture,
            method=project.default_method or default_method(),
            params=project.default_params,
            status="failed",
            error=f"project default parameters: {exc}",
        )
        return None
    run = DetectionRun.objects.create(capture=capture, method=method, params=params)
    enqueue("detect", run.pk)
    return run


def detect_run(run):
    """Run a claimed detection and store candidates, signals and timings on the row."""
    jobs.guard(DETECT, run)


def _detect(run, take=None):
    take = read_take(run.capture) if take is None else take
    # Runs of the default method detect with the project's newest learnt model.
    result, model_fields = adaptation.detect(run, take)
    candidates = [
        {"frame": int(f), "confidence": round(float(c), 4)}
        for f, c in zip(result.cuts, result.confidence, strict=True)
    ]
    signals = {name: np.asarray(v, dtype="<f4") for name, v in result.signals.items()}
    storage.save_npz(run.signals, "signals.npz", signals)
    finished = run.finish(
        candidates=candidates,
        timings={k: round(float(v), 4) for k, v in result.timings.items()},
        signals=run.signals.name,
        finished_at=timezone.now(),
        **model_fields,
    )
    if finished:
        # Reviews opened while this run was computing start from its candidates now.
        do_take_in_candidates(run)
    else:
        cleanup.forget(run.signals)


def do_redetect(capture, user):
    """Queue a new detection of ``capture`` with the project's method, parameters and
    newest model, for a capture nobody has started reviewing.

    A review is started as soon as someone opens the capture for review (its candidates
    are copied into the review then); new candidates would not reach that review, so
    re-detection is refused with the annotators' names.
    """
    if capture.status != "ready":
        raise NotReady(f"capture {capture.pk} is {capture.status}; detection needs a ready capture")
    project = capture.project
    with transaction.atomic():
        # The project row before the capture's, as every transaction that locks both
        # does (starting a run locks the project to count its runs; see quotas).
        Project.objects.select_for_update().filter(pk=project.pk).first()
        # One re-detection or review start at a time per capture.
        Capture.objects.select_for_update().filter(pk=capture.pk).first()
        names = sorted(capture.reviews.values_list("annotator__username", flat=True))
        if names:
            raise ReviewStarted(
                f"capture: {', '.join(names)} started reviewing {capture.name!r}; "
                "re-detection would change the candidates under their review"
            )
        if capture.runs.filter(status__in=("queued", "processing")).exists():
            raise NotReady(f"capture {capture.pk} already has a detection queued or running")
        return do_start_run(capture, user, project.default_method, project.default_params)


INGEST = register(Kind("ingest", Capture, "Ingest", _ingest, "CUTROOM_INGEST_TIME_LIMIT"))
DETECT = register(Kind("detect", DetectionRun, "Detection", _detect, "CUTROOM_DETECT_TIME_LIMIT"))
