"""Retraining a project's cut model: how long for a project of 50 reviewed 5-minute takes.

Real service code on the embedded default (a temporary SQLite database and media folder):
50 synthetic 5-minute, 120 fps takes with known boundaries are stored as BVH captures,
each with a submitted review whose kept cuts are the true boundaries. The training job
(`segmentation.services.adaptation.train_project_model`, what the Celery task runs once it
has claimed the row) is timed end to end, then its two parts apart: reading the takes
and fitting (`motionlib.adapt.fit_cut_model`). The first training parses the stored BVH
originals and caches them (`segmentation.takecache`); the target is for the retrainings
after it, which read the cache, as every retraining after a submit does.

    .venv/bin/python benchmarks/retrain.py [--takes 50] [--minutes 5] [--repeats 3]

Target: training <= 10 s on one core (CPU seconds of the job; wall time printed too).
"""

import argparse
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

from harness import start_django

TARGET_SECONDS = 10.0


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--takes", type=int, default=50)
    parser.add_argument("--minutes", type=float, default=5.0)
    parser.add_argument("--fps", type=float, default=120.0)
    parser.add_argument("--repeats", type=int, default=3, help="trainings (the first fills the cache)")
    return parser.parse_args()


def build_project(n_takes, minutes, fps):
    """A project whose ``n_takes`` captures each have a submitted review cut at the truth."""
    import io

    from django.contrib.auth import get_user_model
    from django.core.files.base import ContentFile

    from motionlib import synth, write_bvh
    from segmentation import services
    from segmentation.models import Capture, Cut, Review

    user = get_user_model().objects.create_user("bench")
    project = services.do_create_project(user, "Retrain bench")
    n_cuts = 0
    for seed in range(n_takes):
        take, segments = synth.generate(seed=seed, fps=fps, duration=minutes * 60)
        text = io.StringIO()
        write_bvh(take, text)
        capture = Capture(project=project, uploaded_by=user, name=f"take_{seed:02d}.bvh",
                          format="bvh", checksum=f"bench-{seed}", status="ready", fps=fps,
                          n_frames=take.n_frames, n_joints=len(take.skeleton.names))
        capture.original.save(capture.name, ContentFile(text.getvalue().encode()), save=False)
        capture.save()
        review = Review.objects.create(capture=capture, annotator=user, status="submitted")
        cuts = [start for start, _stop, _label in segments[1:]]
        Cut.objects.bulk_create(Cut(review=review, origin="inserted", fate="accepted", frame=f)
                                for f in cuts)
        n_cuts += len(cuts)
    return project, n_cuts


def time_training(project):
    from segmentation.models import ProjectCutModel
    from segmentation.services import adaptation

    job = ProjectCutModel.objects.create(project=project)
    assert ProjectCutModel.objects.claim(job.pk, f"bench-{job.pk}")
    job.refresh_from_db()
    started, cpu = time.perf_counter(), time.process_time()
    adaptation.train_project_model(job)
    total, cpu = time.perf_counter() - started, time.process_time() - cpu
    job.refresh_from_db()
    if job.status != "ready":
        sys.exit(f"training failed: {job.error}")
    return total, cpu, job


def time_parts(project):
    from motionlib import adapt
    from segmentation.services import adaptation

    started = time.process_time()
    examples = adaptation.project_examples(project.pk)
    takes = [(adaptation.example_take(capture), cuts) for capture, cuts in examples]
    read = time.process_time() - started
    started = time.process_time()
    adapt.fit_cut_model(takes)
    return read, time.process_time() - started


def main():
    args = parse_args()
    # "On one core": numpy (imported with Django below) must not fan out to other cores.
    for name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(name, "1")
    var = Path(tempfile.mkdtemp(prefix="cutroom-retrain-"))
    try:
        run(args, var)
    finally:
        shutil.rmtree(var, ignore_errors=True)


def run(args, var):
    start_django(unset=("DATABASE_URL", "CELERY_BROKER_URL", "CUTROOM_MEDIA_ROOT", "CELERY_BROKER_DIR"),
                 CUTROOM_VAR_DIR=str(var))
    built = time.perf_counter()
    project, n_cuts = build_project(args.takes, args.minutes, args.fps)
    print(f"load: {args.takes} reviewed takes x {args.minutes:g} min at {args.fps:g} fps "
          f"({args.takes * round(args.minutes * 60 * args.fps):,} frames, {n_cuts} human cuts), "
          f"BVH on local disk, SQLite; built in {time.perf_counter() - built:.1f} s; "
          f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.1f}")
    rows = []
    for repeat in range(args.repeats):
        # The first training parses every original and caches it (segmentation.takecache);
        # the later ones, like every retraining after a submit, read the cache.
        state = "cold cache" if repeat == 0 else "warm cache"
        total, cpu, job = time_training(project)
        read, fit = time_parts(project)
        if repeat:
            rows.append((total, cpu, read, fit))
        print(f"  training {repeat + 1} ({state}): {total:.2f} s wall, {cpu:.2f} s CPU (model "
              f"v{job.version}, {job.n_takes} takes, {job.n_cuts} cuts); then apart, warm: "
              f"read {read:.2f} s CPU, fit {fit:.2f} s CPU")
    if not rows:
        sys.exit("--repeats must be at least 2: the first training fills the cache")
    print(f"\nretraining with the parsed takes cached ({len(rows)} repeats):")
    print(f"{'':30}{'median':>10}{'min':>10}{'max':>10}")
    names = ("training job, wall (s)", "training job, CPU (s)", "  reading takes, CPU (s)",
             "  fitting, CPU (s)")
    for column, name in enumerate(names):
        values = [row[column] for row in rows]
        print(f"{name:30}{statistics.median(values):>10.2f}{min(values):>10.2f}{max(values):>10.2f}")
    # CPU seconds of this single-threaded process: what the job costs one core, even when
    # the machine is shared (its wall time then also counts the other processes).
    median = statistics.median(row[1] for row in rows)
    verdict = "meets" if median <= TARGET_SECONDS else "MISSES"
    print(f"\ntarget: training <= {TARGET_SECONDS:g} s on one core -> median {median:.2f} s CPU "
          f"{verdict} it")


if __name__ == "__main__":
    main()
