"""Submitting a review of a take of many points: what the web request itself costs.

Real service code on the embedded default (a temporary SQLite database and media folder):
a CSV take of ``--points`` points over ``--frames`` frames (random walks, seeded) is
uploaded and ingested; a review with three labelled segments is submitted. Timed, in the
same run:

1. the submit as it is now (``do_submit_review``): the library rows are left to a worker's
   job (``refresh_library``), so the request only queues it;
2. the submit as it was: the request built and described the rows itself, holding the
   database's write lock (``library.refresh_capture_library`` with the capture counted as
   built in the request: what a submit did for a take of fewer than
   ``CUTROOM_DESCRIBE_INLINE`` joint positions);
3. the worker's job for the same rows (``build_library``), off the request.

    .venv/bin/python -m benchmarks submit-points -- [--points 1000] [--frames 160]
"""

import argparse
import io
import os
import resource
import time

import numpy as np

from benchmarks.harness.service import in_scratch_installation


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1000)
    parser.add_argument("--frames", type=int, default=160)
    parser.add_argument("--repeats", type=int, default=3)
    return parser.parse_args()


def points_csv(n_points, n_frames, seed=0):
    rng = np.random.default_rng(seed)
    walk = np.cumsum(rng.normal(0, 0.01, (n_frames, n_points, 3)), axis=0) + rng.normal(
        0, 1, (1, n_points, 3))
    out = io.StringIO()
    out.write("# fps=60 unit=m up=y\nframe,")
    out.write(",".join(f"p{i}_{a}" for i in range(n_points) for a in "xyz") + "\n")
    for frame, row in enumerate(walk.reshape(n_frames, -1)):
        out.write(f"{frame}," + ",".join(f"{v:.5f}" for v in row) + "\n")
    return out.getvalue().encode()


def submitted_review(project, user, capture, n_frames):
    from segmentation import services

    review = services.get_or_create_review(capture, user)
    for cut in list(review.cuts.all()):
        services.do_change_cut(review, user, cut, review.version, fate="deleted")
    for frame in (n_frames // 3, 2 * n_frames // 3):
        services.do_insert_cut(review, user, frame, review.version)
    for index in range(3):
        services.do_label_segment(review, user, index, "walk", review.version)
    return review


def main():
    args = parse_args()
    in_scratch_installation("cutroom-submit-points-", run, args)


def run(args, var):

    from django.contrib.auth import get_user_model
    from django.core.files.uploadedfile import SimpleUploadedFile
    from django.db import transaction

    from segmentation import services, tasks
    from segmentation.models import Capture, LibrarySegment, Review
    from segmentation.services import library

    print(f"load: one take of {args.points} points x {args.frames} frames (CSV), a review of "
          f"3 labelled segments; {args.repeats} submits per case; SQLite; "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    users = get_user_model().objects
    user = users.create_user("bench")
    project = services.do_create_project(user, "Submit bench")
    services.do_add_label(project, "walk", "#2563eb", "1")
    upload = SimpleUploadedFile("points.csv", points_csv(args.points, args.frames))
    capture, _ = services.do_upload_capture(project, user, upload)
    tasks.ingest(capture.pk)
    capture = Capture.objects.get(pk=capture.pk)
    assert capture.status == "ready", capture.error

    def timed(work):
        walls = []
        for _ in range(args.repeats):
            Review.objects.filter(capture=capture).delete()
            LibrarySegment.objects.filter(capture=capture).delete()
            review = submitted_review(project, user, capture, capture.n_frames)
            start = time.perf_counter()
            work(review)
            walls.append(time.perf_counter() - start)
        return float(np.median(walls))

    def now(review):
        services.do_submit_review(review, user, review.version)

    def before(review):
        services.do_submit_review(review, user, review.version)  # queues the job, as now
        with transaction.atomic():  # ... then what the request used to do itself
            built = library.built_in_request
            library.built_in_request = lambda capture: True
            try:
                library.refresh_capture_library(capture)
            finally:
                library.built_in_request = built

    def job(review):
        services.do_submit_review(review, user, review.version)
        start = time.perf_counter()
        tasks.refresh_library(capture.pk)
        job.wall = time.perf_counter() - start

    print(f"\n{'case':<62}{'median s':>10}")
    print(f"{'1. submit now (rows queued for a worker)':<62}{timed(now):>10.3f}")
    print(f"{'2. submit before (rows built and described in the request)':<62}"
          f"{timed(before):>10.3f}")
    timed(job)
    print(f"{'3. the worker job building them (off the request)':<62}{job.wall:>10.3f}")
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    print(f"\npeak RSS of this process: {peak:.0f} MB")


if __name__ == "__main__":
    main()
