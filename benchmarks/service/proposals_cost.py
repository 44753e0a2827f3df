"""What an annotator's own proposed labels cost: a 60-minute take, a pool of reviewed takes.

Real service code on the embedded default (a temporary SQLite database and media folder):
``--takes`` synthetic 5-minute, 120 fps takes are one annotator's submitted reviews, their
segments labelled with the true actions (the library rows the ``suggest`` job reads as
the annotator's pool); a synthetic 60-minute, 120 fps take is the capture they open, cut
at its true boundaries. Parsed takes are put in the parsed-take cache directly (no BVH
text: what is timed starts from a parsed take, as a worker's does after ingest).
Timed, CPU seconds of this one-threaded process (wall in brackets):

1. the 60-minute take's frame descriptors, first time (computed from the parsed take,
   then stored beside it), and read back from storage;
2. the pool's frame model, fitted with the held-out check, from stored descriptors;
3. ``proposals.propose_spans`` for every segment of the 60-minute take: what the
   ``suggest`` job pays when the annotator opens it (fit, check, posterior, proposals),
   with every descriptor stored, and with the pool's stored but the take's not.

    .venv/bin/python -m benchmarks proposals-cost -- [--takes 50] [--hour-minutes 60]

Target: an annotator's proposals for a 60-minute take within seconds (<= 5 s on one core
with stored descriptors, the case after the first open of any take).
"""

import argparse
import os
import time

from benchmarks.harness.service import in_scratch_installation

TARGET_SECONDS = 5.0


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--takes", type=int, default=50)
    parser.add_argument("--minutes", type=float, default=5.0)
    parser.add_argument("--hour-minutes", type=float, default=60.0)
    parser.add_argument("--fps", type=float, default=120.0)
    return parser.parse_args()


def timed(work):
    wall, cpu = time.perf_counter(), time.process_time()
    out = work()
    return out, time.process_time() - cpu, time.perf_counter() - wall


def stored_capture(project, user, name, seed, minutes, fps):
    """A ready capture whose parsed take is in the parsed-take cache; its true segments."""
    from motionlib import synth
    from segmentation.files import takecache
    from segmentation.models import Capture

    take, segments = synth.generate(seed=seed, fps=fps, duration=minutes * 60)
    capture = Capture.objects.create(project=project, uploaded_by=user, name=name, format="bvh",
                                     checksum=f"bench-{seed}-{minutes}", status="ready", fps=fps,
                                     n_frames=take.n_frames, n_joints=len(take.skeleton.names))
    capture.original.name = f"captures/bench/{name}"  # never read: the parsed take is cached
    capture.save()
    takecache.read_cached(capture, lambda _capture: take)
    return capture, segments


def build(args):
    from django.contrib.auth import get_user_model

    from segmentation import services
    from segmentation.models import LibrarySegment, Review

    user = get_user_model().objects.create_user("annotator")
    project = services.do_create_project(user, "Proposals bench")
    labels = {}
    rows = []
    for seed in range(args.takes):
        capture, segments = stored_capture(project, user, f"take_{seed:02d}.bvh", seed,
                                           args.minutes, args.fps)
        review = Review.objects.create(capture=capture, annotator=user, status="submitted")
        for start, stop, action in segments:
            if action not in labels:
                labels[action] = services.do_add_label(project, action)
            rows.append(LibrarySegment(project=project, capture=capture, review=review,
                                       annotator=user, label=labels[action], start=start,
                                       stop=stop, duration=(stop - start) / args.fps))
    LibrarySegment.objects.bulk_create(rows)
    hour, truth = stored_capture(project, user, "hour.bvh", 10_000, args.hour_minutes, args.fps)
    pool = LibrarySegment.objects.filter(project=project).exclude(capture=hour)
    return hour, [(a, b) for a, b, _ in truth], pool


def main():
    in_scratch_installation("cutroom-proposals-", run, parse_args())


def run(args, var):
    from segmentation.files import takecache
    from segmentation.models import Capture
    from segmentation.similar import proposals

    built = time.perf_counter()
    hour, spans, pool = build(args)
    print(f"load: one annotator's pool of {args.takes} reviewed takes x {args.minutes:g} min, "
          f"a {args.hour_minutes:g}-minute take ({hour.n_frames:,} frames at {args.fps:g} fps, "
          f"{len(spans)} segments); SQLite, local disk; built in "
          f"{time.perf_counter() - built:.0f} s; {os.cpu_count()} cores, load average "
          f"{os.getloadavg()[0]:.1f}")
    print(f"{'case':<72}{'CPU s':>8}{'wall s':>8}")

    def show(case, cpu, wall):
        print(f"{case:<72}{cpu:>8.2f}{wall:>8.2f}", flush=True)

    _, cpu, wall = timed(lambda: [proposals.frames_of(c) for c in
                                  Capture.objects.exclude(pk=hour.pk)])
    show(f"0. the pool's {args.takes} takes' descriptors, first time (set-up)", cpu, wall)
    cold = lambda: proposals.propose_spans(hour, pool, spans)  # noqa: E731
    found, cpu, wall = timed(cold)
    show("3b. proposals, the 60-minute take's descriptors not stored yet", cpu, wall)
    _, cpu, wall = timed(lambda: proposals.frames_of(hour))
    show("1b. the 60-minute take's descriptors, read back from storage", cpu, wall)
    storage = Capture._meta.get_field("original").storage
    storage.delete(takecache.StoredStudies.name(takecache.example_key(hour) + "-frames"))
    _, cpu, wall = timed(lambda: proposals.frames_of(hour))
    show("1a. the 60-minute take's descriptors, computed from the parsed take", cpu, wall)
    examples = proposals.pool_examples(pool)
    model, cpu, wall = timed(lambda: proposals.checked_fit(examples))
    check = proposals.held_out(model, examples) if model else None
    show(f"2. the pool's frame model with its held-out check "
         f"({'passed' if model else 'refused'})", cpu, wall)
    warm = []
    for _ in range(3):
        found, cpu, wall = timed(cold)
        warm.append(cpu)
        show("3a. proposals, every descriptor stored", cpu, wall)
    named = sum(1 for label, _ in found if label is not None)
    if check is not None:
        print(f"\nheld-out check: label accuracy {check.accuracy:.3f} on {check.takes} held-out "
              f"takes against {check.constant:.3f} for the best constant proposal")
    median = sorted(warm)[1]
    print(f"{named} of {len(spans)} segments of the 60-minute take proposed a label.")
    print(f"target: proposals for a 60-minute take <= {TARGET_SECONDS:g} s on one core with "
          f"stored descriptors -> median {median:.2f} s CPU "
          f"{'meets' if median <= TARGET_SECONDS else 'MISSES'} it")
