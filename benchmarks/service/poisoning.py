"""One annotator against a project's model: how the model in use cuts the next takes when
one annotator under-cuts or over-cuts 3 of a project's 10 reviewed takes (the target),
or 5 of 7 (a young project, where one annotator is most of the reviews).

Real service code on the embedded default (a temporary SQLite database and media folder),
synthetic takes with known boundaries (``motionlib.synth``) stored as BVH captures. An
honest annotator reviews takes to their true cuts; the poisoner's reviews either keep no
cut (under-cut) or add, in every true segment, the detector's candidate nearest its middle
(over-cut: about twice the true cuts, at frames the learner can learn). Two ways the
poisoner's takes reach the project:

- *shared*: every take was reviewed honestly, then the poisoner re-reviews theirs;
- *alone*: the poisoner is the only reviewer of their takes, reviewed after the others;
- *first*: the poisoner is the only reviewer of their takes and reviews them before anyone
  else (the project trains on them alone first), then the honest annotator reviews the rest.

Both paths in the same run, on the same reviews:

- *old*: the example of a take is its most recently submitted review, and every training
  replaces the model (the service before the consensus and the gate);
- *new*: gold, else the consensus of the take's submitted reviews, and the gate
  (``segmentation.services.model_gate``): the project trains once on its first reviews
  (all takes in *shared*, the honest ones in *alone*), then once more after the
  poisoner's submits, and the model in use afterwards is scored.

Each model is scored on held-out takes of other seeds (F1 within 1 s, review edits per
true cut, pooled); "clean" is the model learnt from honest reviews of the same takes.

    .venv/bin/python -m benchmarks poisoning -- [--minutes 1] [--next 5]

Target: the poisoner moves the F1 on the next takes by < 0.05. ``cuts`` is what the model
in use proposes on the held-out takes against their true cuts (an under-cut model proposes
few, an over-cut one many). To compare with the service of another revision in the same
run: ``python -m benchmarks poisoning --against REV`` (that revision's *new* path is its
service as it was).
"""

import argparse
import io
import os
import sys
import time

from benchmarks.harness.service import in_scratch_installation

FPS = 120.0
# (takes in the project, which of them the poisoner reviews)
PROJECTS = ((10, (2, 5, 8)), (7, (2, 3, 4, 5, 6)))
TARGET_F1_MOVE = 0.05


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=1.0, help="length of each take")
    parser.add_argument("--next", type=int, default=5, help="held-out takes scored")
    return parser.parse_args()


def truth(seed, minutes):
    from motionlib import synth

    take, segments = synth.generate(seed=seed, fps=FPS, duration=minutes * 60)
    return take, [start for start, _stop, _label in segments[1:]]


def poisoned_cuts(kind, cuts, take):
    """The poisoner's cuts: none (under-cut), or the true ones plus, in every true segment,
    the detector's candidate nearest its middle (over-cut: a cut the learner can learn,
    as an annotator who keeps weak candidates would), about twice the true count."""
    if kind == "under-cut":
        return []
    from motionlib import adapt

    candidates = adapt.placed(adapt.CutModel.zero_shot(), adapt.study(take))
    bounds = [0, *cuts, take.n_frames]
    extra = set()
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        inside = [int(f) for f in candidates if a + FPS <= f <= b - FPS]
        if inside:
            extra.add(min(inside, key=lambda f: abs(f - (a + b) // 2)))
    return sorted({*cuts, *extra})


class Project:
    """A project of ``n_takes`` stored captures, and the users who review them."""

    def __init__(self, name, minutes, n_takes):
        from django.contrib.auth import get_user_model

        from segmentation import services

        users = get_user_model().objects
        self.honest = users.get_or_create(username="honest")[0]
        self.poisoner = users.get_or_create(username="poisoner")[0]
        self.project = services.do_create_project(self.honest, name)
        self.captures = [self.capture(seed, minutes) for seed in range(n_takes)]

    def capture(self, seed, minutes):
        from django.core.files.base import ContentFile

        from motionlib import write_bvh
        from segmentation.models import Capture

        take, cuts = truth(seed, minutes)
        text = io.StringIO()
        write_bvh(take, text)
        capture = Capture(project=self.project, uploaded_by=self.honest, name=f"take_{seed:02d}.bvh",
                          format="bvh", checksum=f"{self.project.pk}-{seed}", status="ready",
                          fps=FPS, n_frames=take.n_frames, n_joints=len(take.skeleton.names))
        capture.original.save(capture.name, ContentFile(text.getvalue().encode()), save=False)
        capture.save()
        capture.truth, capture.take = cuts, take
        return capture

    def review(self, capture, user, cuts):
        from django.utils import timezone

        from segmentation.models import Cut, Review

        review = Review.objects.create(capture=capture, annotator=user, status="submitted",
                                       submitted_at=timezone.now())
        Cut.objects.bulk_create(Cut(review=review, origin="inserted", fate="accepted", frame=f)
                                for f in cuts)
        time.sleep(0.002)  # distinct submit times: "the latest review" is well defined

    def train(self):
        from segmentation.models import ProjectCutModel
        from segmentation.services import adaptation

        job = ProjectCutModel.objects.create(project=self.project)
        assert ProjectCutModel.objects.claim(job.pk, f"bench-{job.pk}")
        job.refresh_from_db()
        adaptation.train_project_model(job)
        job.refresh_from_db()
        if job.status != "ready":
            sys.exit(f"training failed: {job.error}")
        return job


def latest_review_examples(project):
    """The old path's examples: each take's most recently submitted review."""
    from segmentation.models import Review

    latest = {}
    for review in (Review.objects.filter(capture__project=project, status="submitted")
                   .order_by("capture_id", "-submitted_at", "-id").prefetch_related("cuts")):
        latest.setdefault(review.capture_id, review)
    return [(review.capture, sorted(c.frame for c in review.kept_cuts())) for review in latest.values()]


def in_use(project):
    from motionlib import adapt
    from segmentation.models import ProjectCutModel

    newest = ProjectCutModel.objects.newest(project.pk)
    return adapt.CutModel.from_json(newest.model) if newest else None


def build(kind, where, minutes, n_takes, which):
    """(old path's model, new path's model in use, what the new path's last training did)."""
    from segmentation.services import adaptation

    p = Project(f"{kind} {where} {n_takes}", minutes, n_takes)
    poisoned = [p.captures[i] for i in which]
    honest = p.captures if where == "shared" else [c for c in p.captures if c not in poisoned]
    if where == "first":
        for capture in poisoned:
            p.review(capture, p.poisoner, poisoned_cuts(kind, capture.truth, capture.take))
        p.train()
        for capture in honest:
            p.review(capture, p.honest, capture.truth)
        job = p.train()
    else:
        for capture in honest:
            p.review(capture, p.honest, capture.truth)
        p.train()
        for capture in poisoned:
            p.review(capture, p.poisoner, poisoned_cuts(kind, capture.truth, capture.take))
        job = p.train()
    old = adaptation.fit_examples(latest_review_examples(p.project), None)
    outcome = job.refused.split(":")[0] if job.refused else f"accepted v{job.version}"
    return old, in_use(p.project), outcome


def score(model, held_out):
    """The model's pooled Figure on the held-out takes (its ``candidates`` are what it
    proposes there)."""
    from motionlib import adapt
    from segmentation.services.model_gate import Figure

    figure = Figure()
    for take, cuts in held_out:
        figure.add(adapt.detect(take, model).cuts.tolist(), cuts, FPS)
    return figure


def cuts(figure):
    """"proposed/true" over the held-out takes."""
    return f"{figure.candidates}/{figure.true_cuts}"


def main():
    in_scratch_installation("cutroom-poisoning-", run, parse_args())


def run(args, var):
    from segmentation.services import adaptation

    started = time.perf_counter()
    held_out = [truth(seed, args.minutes) for seed in range(100, 100 + args.next)]
    zero = score(None, held_out)
    print(f"load: synthetic takes of {args.minutes:g} min at {FPS:g} fps; scored on {args.next} "
          f"held-out takes ({sum(len(c) for _, c in held_out)} true cuts); {os.cpu_count()} cores, "
          f"load average {os.getloadavg()[0]:.1f}")
    print(f"zero-shot: F1 {zero.f1:.3f}, {zero.edits_per_cut:.2f} edits per true cut, "
          f"{zero.candidates} cuts\n")
    print(f"| {'project':<14} | {'poisoner':<10} | {'their takes':<11} | {'path':<4} | {'last training':<14} "
          f"| {'F1':>6} | {'F1 - clean':>10} | {'edits/cut':>9} | {'cuts':>7} | {'< 0.05':<6} |")
    print(f"|{'-' * 16}|{'-' * 12}|{'-' * 13}|{'-' * 6}|{'-' * 16}|{'-' * 8}|{'-' * 12}|{'-' * 11}"
          f"|{'-' * 9}|{'-' * 8}|")
    worst = {"old": 0.0, "new": 0.0}
    for n_takes, which in PROJECTS:
        clean_project = Project(f"clean {n_takes}", args.minutes, n_takes)
        for capture in clean_project.captures:
            clean_project.review(capture, clean_project.honest, capture.truth)
        examples = adaptation.project_examples(clean_project.project.pk)
        clean = score(adaptation.fit_examples(examples, None), held_out)
        label = f"{len(which)} of {n_takes} bad"
        print(f"| {label:<14} | {'(none)':<10} | {'':<11} | {'':<4} | {'clean':<14} | {clean.f1:>6.3f} "
              f"| {0.0:>+10.3f} | {clean.edits_per_cut:>9.2f} | {cuts(clean):>7} | {'':<6} |")
        for kind in ("under-cut", "over-cut"):
            for where in ("shared", "alone", "first"):
                old, new, outcome = build(kind, where, args.minutes, n_takes, which)
                for path, model, last in (("old", old, "accepted"), ("new", new, outcome)):
                    figure = score(model, held_out)
                    move = figure.f1 - clean.f1
                    worst[path] = max(worst[path], abs(move))
                    print(f"| {label:<14} | {kind:<10} | {where:<11} | {path:<4} | {last:<14} "
                          f"| {figure.f1:>6.3f} | {move:>+10.3f} | {figure.edits_per_cut:>9.2f} | "
                          f"{cuts(figure):>7} | {'yes' if abs(move) < TARGET_F1_MOVE else 'NO':<6} |", flush=True)
    print(f"\ntarget: the poisoner moves F1 on the next takes by < {TARGET_F1_MOVE} -> largest move: "
          f"old path {worst['old']:.3f}, new path {worst['new']:.3f} "
          f"({'meets' if worst['new'] < TARGET_F1_MOVE else 'MISSES'} it); "
          f"ran in {time.perf_counter() - started:.0f} s")
