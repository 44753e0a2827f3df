"""Learning each project's cutting from its own reviews.

A project's examples are its reviewed takes: the gold version of a capture where one was
saved, else the consensus of all its submitted reviews (``consensus.consensus_cuts``, a
tie between annotators settled by the project's current model as a half-vote referee:
one example per take, so every take weighs the same and "learnt from N reviewed takes"
counts takes). Each example knows its source (gold, shared, or one annotator alone):
one annotator's own takes weigh together at most what the rest of the project does
(``annotator_weights``), and an annotator whose takes keep far fewer or far more cuts
than the zero-shot detector proposes there is not learnt from (``implausible``). A take
that cannot be read or is too short is left out with a note (``learnable``), never
failing the training.

After a submit or a gold save, ``request_training`` queues one training per project
(requests made while one waits join it); a worker trains with
``motionlib.adapt.fit_cut_model``, scores the new model against the current one on
reviewed takes each did not learn from, by source (``model_gate``), and stores it as the
project's next version only if it is accepted; a refused model is stored with the reason
and no version. Runs of the ``default`` method detect with the newest version; a project
without one uses the zero-shot detector. A failed training stores its reason and leaves
the newest version in use. The rules and their reasons: docs/learning.md.

What the fit learnt from each reviewed take (its study) is stored beside the parsed take
(``takecache.StoredStudies``), so a retraining after one more submit reads and analyses
that one take; the others' studies are used as long as their cuts and the detector's
settings are unchanged.
"""

import dataclasses
import functools
import logging
import time
from collections import defaultdict

import numpy as np
from django.conf import settings
from django.db import IntegrityError, transaction
from django.db.models import Max
from django.utils import timezone

from motionlib.consensus import consensus_cuts
from motionlib.errors import MotionlibError
from motionlib.segmenters import get_segmenter
from segmentation.errors import CutroomError, Invalid
from segmentation.files import takecache
from segmentation.files.storage import read_take
from segmentation.models import Capture, Label, Membership, ProjectCutModel, Review
from segmentation.services import jobs, model_gate
from segmentation.services.jobs import Kind, register

log = logging.getLogger(__name__)


# ---- requesting a training ---------------------------------------------------------------


def on_examples_changed(project_id):
    """Called inside a submit or gold-save transaction: retrain once it commits.

    The request is made after the commit so that a training claimed from now on reads the
    new example; a training already running read the examples before it and is followed
    by the one queued here.
    """
    # robust: the submit is committed by then; a failure here is logged (the next submit
    # asks again) instead of turning the submit's answer into an error.
    transaction.on_commit(lambda: request_training(project_id), robust=True)


def request_training(project_id):
    """Queue a training of the project's model, unless one is queued already (it will
    read the current examples when it starts). Returns the queued row, or None.

    The job is sent ``CUTROOM_RETRAIN_DELAY`` seconds later, so that a burst of submits
    costs one training.
    """
    if ProjectCutModel.objects.filter(project_id=project_id, status="queued").exists():
        return None
    try:
        with transaction.atomic():
            job = ProjectCutModel.objects.create(project_id=project_id)
            # The row stays queued if the broker is down; the sweep sends it again later.
            jobs.enqueue("retrain", job.pk, countdown=settings.CUTROOM_RETRAIN_DELAY)
    except IntegrityError:
        return None  # a concurrent request queued it (one queued training per project)
    return job


# ---- training ----------------------------------------------------------------------------


# Two annotators' cuts within this many seconds are the same cut (the learner's and the
# gate's matching tolerance too).
CONSENSUS_S = 1.0


def project_examples(project_id):
    """``[(capture, cuts)]``, by capture id: each reviewed ready capture of the project with
    its gold cuts, else the consensus of the kept cuts of all its submitted reviews
    (0-based frames). ``project_pool`` says whose each one is."""
    return project_pool(project_id)[0]


def project_pool(project_id, referee=None):
    """(``project_examples``, sources): the source of each example by capture id —
    ``model_gate.GOLD`` (a reviewer's gold version), ``model_gate.SHARED`` (the consensus
    of two or more annotators' reviews) or the id of the one annotator who reviewed it.

    ``referee(capture)``, when given, is the cut frames a voter of no annotator proposes
    on the take (the project's current model): it settles a tie between annotators
    (``consensus_cuts``); None when it cannot say.
    """
    captures = Capture.objects.filter(project_id=project_id, status="ready").select_related(
        "adjudication"
    ).order_by("id")
    reviews = (
        Review.objects.filter(capture__project_id=project_id, status="submitted")
        .prefetch_related("cuts")
        .order_by("capture_id", "id")
    )
    submitted = defaultdict(list)
    for review in reviews:
        submitted[review.capture_id].append((review.annotator_id, [c.frame for c in review.kept_cuts()]))
    examples, sources = [], {}
    for capture in captures:
        gold = getattr(capture, "adjudication", None)
        if gold is not None:
            examples.append((capture, sorted(gold.cuts)))
            sources[capture.pk] = model_gate.GOLD
        elif capture.pk in submitted:
            annotators = {annotator for annotator, _cuts in submitted[capture.pk]}
            votes = [cuts for _annotator, cuts in submitted[capture.pk]]
            tie = referee(capture) if referee is not None and len(votes) > 1 else None
            tolerance = int(round(CONSENSUS_S * capture.fps))
            examples.append((capture, consensus_cuts(votes, tolerance, referee=tie)))
            sources[capture.pk] = model_gate.SHARED if len(annotators) > 1 else annotators.pop()
    return examples, sources


def annotator_weights(examples, sources):
    """{capture id: weight} for ``motionlib.adapt.Example.weight``: the takes one annotator
    alone reviewed weigh together at most as much as all the project's other examples
    (gold versions, takes several annotators reviewed, other annotators' takes), each
    ``min(1, others / theirs)``; every other example 1. An annotator who is the whole
    project (nothing else to weigh against) keeps weight 1: the gate's count check is
    what stands against them."""
    lone = defaultdict(list)
    for capture, _cuts in examples:
        if sources.get(capture.pk) not in (model_gate.GOLD, model_gate.SHARED, None):
            lone[sources[capture.pk]].append(capture.pk)
    weights = {capture.pk: 1.0 for capture, _cuts in examples}
    for annotator, pks in lone.items():
        others = len(examples) - len(pks)
        scale = IMPLAUSIBLE_WEIGHT if annotator in sources.get(model_gate.IMPLAUSIBLE, ()) else 1.0
        for pk in pks:
            weights[pk] = scale * (min(1.0, others / len(pks)) if others else 1.0)
    return weights


# What each take of an implausible annotator (``implausible``) counts at most in the fit.
IMPLAUSIBLE_WEIGHT = 0.1


def implausible(examples, sources, zero):
    """The annotators whose takes, reviewed by them alone, keep far fewer or far more cuts
    than the zero-shot detector proposes there (pooled over their takes where it proposes
    any; the gate's ``COUNT_FACTOR``): the signature of one who deletes every candidate or
    adds cuts everywhere. The zero-shot detector belongs to no annotator, so it can tell
    which of two annotators who disagree is the odd one. ``zero``: {capture id: zero-shot
    cuts} for those takes."""
    kept, proposed = defaultdict(int), defaultdict(int)
    for capture, cuts in examples:
        if zero.get(capture.pk):
            kept[sources[capture.pk]] += len(cuts)
            proposed[sources[capture.pk]] += zero[capture.pk]
    return frozenset(a for a in kept if not proposed[a] / model_gate.COUNT_FACTOR <= kept[a]
                     <= proposed[a] * model_gate.COUNT_FACTOR)


def learnable(examples, studies):
    """(the examples a fit can learn from, a note on each other one): a take that cannot
    be read or is too short to analyse, or whose cuts lie outside it, is left out and
    named with the reason, so that one bad take never fails the project's training. Each
    kept take's study is made here (and stored), which the fit then reads."""
    from motionlib import adapt

    kept, notes = [], []
    for capture, cuts in examples:
        try:
            n = capture.n_frames or 0
            outside = [f for f in cuts if not 0 < f < n]
            if outside:
                raise Invalid(f"cut {outside[0]} is outside the take ({n} frames)")
            adapt.example_study(example(capture, cuts), studies=studies)
        except (CutroomError, MotionlibError, ValueError, FloatingPointError) as exc:
            # The note names the capture once; the errors name it in their own words.
            reason = str(exc).removeprefix(f"{example_name(capture)}: ").removeprefix(
                f"reviewed capture {capture.pk} ({capture.name!r}) ")
            notes.append(f"capture {capture.pk} ({capture.name!r}) skipped: {reason}")
            continue
        kept.append((capture, cuts))
    return kept, notes


def example_segments(capture, cuts):
    """The capture's labelled segments as the frame model learns them: ``(start, stop,
    label id as text or "")``. Gold where saved; else the segments between the example's
    (consensus) cuts, each with the label its submitted reviews give most of its frames
    (ids, so that a rename changes nothing the model keeps)."""
    n = capture.n_frames or 0
    gold = getattr(capture, "adjudication", None)
    if gold is not None:
        bounds = [0, *sorted(gold.cuts), n]
        return [(a, b, str(lab) if lab else "")
                for a, b, lab in zip(bounds[:-1], bounds[1:], gold.labels, strict=False)]
    reviews = list(Review.objects.filter(capture=capture, status="submitted"))
    labelled = [(start, stop, label) for review in reviews
                for _, start, stop, label in review.segments(label="label_id")
                if label is not None]
    names = sorted({label for _, _, label in labelled})
    votes = np.zeros((n, len(names)))
    for start, stop, label in labelled:
        votes[start:stop, names.index(label)] += 1
    bounds = [0, *cuts, n]
    out = []
    for a, b in zip(bounds[:-1], bounds[1:], strict=True):
        mass = votes[a:b].sum(axis=0)
        # a segment its reviewers mostly left unlabelled stays unlabelled
        named = len(names) and b > a and mass.max() * 2 >= (b - a) * len(reviews)
        out.append((a, b, str(names[int(np.argmax(mass))]) if named else ""))
    return out


def fit_labels(examples):
    """The project's frame model (``motionlib.labelling``) as stored text; "" when no
    reviewed take carries a label, or when the model fails its held-out check
    (``proposals.checked_fit``: its proposals must match more reviewed frames than a
    constant proposal would). Each take's descriptors are read from storage once stored."""
    from segmentation.similar import proposals as proposed

    chosen = [proposed.frames_of(capture, example_segments(capture, cuts), example_take)
              for capture, cuts in examples]
    model = proposed.checked_fit(chosen)
    return model.to_json() if model is not None else ""


def example_name(capture):
    """How training names a reviewed capture: motionlib names a take by its path when it
    has one, and the stored file's name is a random folder away from what the studio knows."""
    return f"capture {capture.pk} ({capture.name})"


def example_take(capture):
    """The capture's take (parsed once, then from ``takecache``), named after the capture
    so that an error names it."""
    try:
        take = takecache.read_cached(capture, read_take)
    except (MotionlibError, CutroomError, OSError) as exc:
        raise Invalid(f"reviewed capture {capture.pk} ({capture.name!r}) cannot be read: {exc}") from exc
    return dataclasses.replace(take, name=example_name(capture), path=None)


def example(capture, cuts, weight=1.0):
    """The capture as an example for ``motionlib.adapt.fit_cut_model``: read (``example_take``)
    only if its stored study does not stand in for it; its key is its content."""
    from motionlib import adapt

    return adapt.Example(
        name=example_name(capture), cuts=cuts, fps=capture.fps,
        n_frames=capture.n_frames, read=functools.partial(example_take, capture),
        key=takecache.example_key(capture), weight=weight,
    )


def train_project_model(job):
    """Train a claimed ProjectCutModel row from the project's current examples, store it
    as the next version (or the reason it failed), then start the training that waited."""
    jobs.guard(RETRAIN, job)


def _train(job):
    started = time.perf_counter()
    stored = takecache.StoredStudies(Capture._meta.get_field("original").storage)
    in_memory = model_gate.FoldStudies(stored)
    # One training at a time per project: no other version appears before this one ends.
    current = ProjectCutModel.objects.newest(job.project_id)
    current_model = _loaded(current.pk, current.version) if current else None
    examples, sources = project_pool(job.project_id, referee=referee_for(current_model, stored))
    if not examples:
        raise Invalid("the project has no submitted review or gold version to learn from")
    examples, skipped = learnable(examples, stored)
    if not examples:
        raise Invalid("no reviewed take can be learnt from: " + "; ".join(skipped))
    zero = {capture.pk: len(_candidates(capture, None, stored)) for capture, _cuts in examples
            if sources[capture.pk] not in (model_gate.GOLD, model_gate.SHARED)}
    odd = implausible(examples, sources, zero)
    sources = {**sources, model_gate.IMPLAUSIBLE: odd}
    # An implausible annotator's takes are not learnt from while there is anything else:
    # the learner's medians and outlier test count takes, and four takes without a cut
    # would outnumber two honest ones there. The gate still scores the model on them.
    pool = [e for e in examples if sources[e[0].pk] not in odd] or examples
    # The full fit first, with the stored studies: they stay those of the examples as they
    # are, which the next training reads (the gate's refits keep theirs in memory).
    candidate = fit_examples(pool, stored, refits=True, sources=sources)
    model = candidate.model
    learnt = set(current.trained_on) if current is not None else set()
    own = [e for e in examples if e[0].pk in learnt]
    # The current model's own examples, refitted only when a take it learnt from is scored.
    own_refits = functools.cache(lambda: fit_examples(own, in_memory, refits=True, sources=sources))
    pooled = {capture.pk for capture, _cuts in pool}

    def candidate_without(capture):
        return candidate.without(_position(pool, capture)) if capture.pk in pooled else model

    verdict = model_gate.judge(
        examples, current, current_model, sources=sources,
        candidate_without=candidate_without,
        current_without=lambda capture: own_refits().without(_position(own, capture)),
        detect=lambda capture, cut_model: _candidates(capture, cut_model, in_memory),
    )
    with transaction.atomic():
        newest = ProjectCutModel.objects.filter(project_id=job.project_id).aggregate(v=Max("version"))
        job.finish(
            version=None if verdict.refused else (newest["v"] or 0) + 1,
            refused=verdict.refused,
            skipped="\n".join(skipped),
            model=model.to_json(),
            labels_model=fit_labels(pool),
            n_takes=model.n_takes,
            n_cuts=model.n_cuts,
            trained_on=[capture.pk for capture, _cuts in pool],
            held_out_takes=verdict.figure.takes,
            held_out_edits_per_cut=round(verdict.figure.edits_per_cut, 4),
            held_out_f1=round(verdict.figure.f1, 4),
            held_out_basis=verdict.basis,
            seconds=round(time.perf_counter() - started, 3),
            finished_at=timezone.now(),
        )


def referee_for(cut_model, studies=None):
    """The referee of ``project_pool`` a training uses: ``_referee`` with the project's
    current model (None: zero-shot)."""
    return functools.partial(_referee, cut_model=cut_model, studies=studies)


def _referee(capture, cut_model, studies):
    """What the project's current model (zero-shot without one) proposes on ``capture``:
    the vote that settles a tie between its annotators; None for a take it cannot read
    (``learnable`` then names it)."""
    try:
        return _candidates(capture, cut_model, studies)
    except (CutroomError, MotionlibError, ValueError, FloatingPointError):
        return None


def fit_examples(examples, studies, refits=False, sources=None):
    """``motionlib.adapt.fit_cut_model`` over ``[(capture, cuts)]``; with ``refits``, the
    ``motionlib.adapt.Refits`` whose ``model`` that is, to refit without one example. With
    ``sources`` (``project_pool``), one annotator's takes are capped (``annotator_weights``)."""
    from motionlib import adapt

    weights = annotator_weights(examples, sources) if sources is not None else {}
    chosen = [example(capture, cuts, weights.get(capture.pk, 1.0)) for capture, cuts in examples]
    if refits:
        return adapt.Refits(chosen, studies=studies)
    return adapt.fit_cut_model(chosen, studies=studies)


def _position(examples, capture):
    return next(i for i, (c, _cuts) in enumerate(examples) if c.pk == capture.pk)


def _candidates(capture, cut_model, studies):
    """The candidate frames the default detector with ``cut_model`` (None: zero-shot)
    proposes on ``capture``'s take, with the detector's own parameters as the fit learns
    from them (a project's ``default_params`` are left out of both).

    A candidate-scorer model (and zero-shot, its prior) chooses among the take's stored
    candidates, which the fit just read or made: the take is not read or analysed again.
    A model of the older threshold format detects on the take as it always did."""
    from motionlib import adapt

    if cut_model is None or isinstance(cut_model, adapt.CutModel):
        arrays = adapt.example_study(example(capture, []), studies=studies)
        return [int(f) for f in adapt.cuts_in(arrays, cut_model or adapt.CutModel.zero_shot())]
    return [int(f) for f in adapt.detect(example_take(capture), cut_model).cuts]


RETRAIN = register(Kind("retrain", ProjectCutModel, "Training", _train, "CUTROOM_RETRAIN_TIME_LIMIT"))


# ---- detecting with the project's model --------------------------------------------------


def detect(run, take):
    """(segmentation, run fields) of ``take`` for ``run``.

    A ``default`` run in a project with a trained model detects with its newest version
    and records it; anything else runs the registry's segmenter as before.
    """
    segmenter = get_segmenter(run.method)
    params = segmenter.validate_params(run.params)
    newest = None
    if run.method == "default":
        newest = ProjectCutModel.objects.newest(run.capture.project_id)
    model = _loaded(newest.pk, newest.version) if newest is not None else None
    if model is None:
        return segmenter(**params).fit_predict(take), {"model_version": None, "model_n_takes": None}
    from motionlib import adapt

    result = adapt.detect(take, model, **params)
    return result, {"model_version": newest.version, "model_n_takes": newest.n_takes,
                    "proposals": proposals(newest, take, result.cuts)}


def proposals(row, take, cuts):
    """``[{"label", "probability"}]`` for each segment between ``cuts``: the label the
    model's frame model finds most likely there (a label id; None for a retired label or
    where the reviewers would most likely leave it unlabelled); [] without a frame model."""
    frames = _loaded_labels(row.pk)
    if frames is None:
        return []
    from motionlib import labelling

    retired = Label.objects.filter(project_id=row.project_id, retired=True).values_list("id", flat=True)
    alive = set(Label.objects.filter(project_id=row.project_id).values_list("id", flat=True))
    # A retired or deleted label is proposed no more: its frames count as unlabelled.
    gone = {name: None for name in frames.names if name and (int(name) in set(retired) or int(name) not in alive)}
    if gone:
        frames = labelling.relabelled(frames, gone)
    post = labelling.posterior(frames, take)
    return [{"label": int(name) if name else None, "probability": p}
            for name, p in labelling.propose(frames, post, cuts, fps=float(take.fps))]


def _loaded_labels(pk):
    text = ProjectCutModel.objects.values_list("labels_model", flat=True).get(pk=pk)
    return _parsed_labels(text, pk) if text else None


@functools.lru_cache(maxsize=32)
def _parsed_labels(text, pk):
    from motionlib import labelling

    try:
        return labelling.FrameModel.from_json(text)
    except ValueError:
        log.exception("frame model (row %s) cannot be read; no label proposals", pk)
        return None


def _loaded(pk, version):
    """A stored model, parsed once per worker process.

    The cache is keyed by the stored text, not the row: a row id can come back after its
    project was deleted (SQLite reuses the highest one), and a model parsed for the old
    row must not stand in for the new one.
    """
    text = ProjectCutModel.objects.values_list("model", flat=True).get(pk=pk)
    return _parsed(text, version, pk)


@functools.lru_cache(maxsize=32)
def _parsed(text, version, pk):
    """A model this version of motionlib cannot read (stored by an older release) is logged
    and detection falls back to the zero-shot detector until the project retrains."""
    from motionlib import adapt

    try:
        return adapt.CutModel.from_json(text)
    except ValueError:
        log.exception("cut model v%s (row %s) cannot be read; detecting zero-shot", version, pk)
        return None


# ---- what the review page shows ----------------------------------------------------------


def adaptation_summary(run, project_id, viewer):
    """What a review page says about adaptation: the model its candidates came from
    (None: zero-shot) with its own held-out figure, the project's current model, why the
    last training failed, and, for the project's reviewers and admins (``viewer``), why its
    model was refused and which reviewed takes it left out: news for those who look after
    the model, not an error, and nothing an annotator can act on."""
    newest = ProjectCutModel.objects.newest(project_id)
    # Trainings end in the order they were asked for (one at a time per project).
    last = (
        ProjectCutModel.objects.filter(project_id=project_id, status__in=("ready", "failed"))
        .order_by("-id")
        .first()
    )
    training = ProjectCutModel.objects.filter(
        project_id=project_id, status__in=("queued", "processing")
    ).exists()
    version = run.model_version if run else None
    oversees = Membership.objects.filter(project_id=project_id, user=viewer,
                                         role__in=("reviewer", "admin")).exists()
    used = newest if newest is not None and newest.version == version else (
        ProjectCutModel.objects.filter(project_id=project_id, version=version).first()
        if version is not None else None
    )
    return {
        "model_version": version,
        "n_takes": run.model_n_takes if run else None,
        "held_out": held_out(used),
        "project_model": (
            {"version": newest.version, "n_takes": newest.n_takes, "n_cuts": newest.n_cuts,
             "held_out": held_out(newest)}
            if newest else None
        ),
        "training": training,
        "training_error": last.error if last is not None and last.status == "failed" else None,
        "training_refused": (last.refused or None) if oversees and last is not None and last.status == "ready" else None,
        "training_skipped": (last.skipped or None) if oversees and last is not None and last.status == "ready" else None,
    }


def held_out(row):
    """A trained model's own figure (``model_gate``): the reviewed takes it was scored on,
    each by a model fitted without it, with the review edits per true cut and F1 there,
    and what those takes' examples came from (``model_gate.basis``; None each for a model
    trained before it was kept): a figure measured on one annotator's own reviews says
    how well the model follows that annotator, and F1 on takes whose reviews keep no cut
    says nothing. None for a model trained before the figure was kept."""
    if row is None or row.held_out_takes is None:
        return None
    basis = row.held_out_basis or {}
    return {"n_takes": row.held_out_takes, "edits_per_cut": row.held_out_edits_per_cut,
            "f1": row.held_out_f1,
            **{key: basis.get(key) for key in ("gold", "shared", "single", "annotators", "true_cuts")}}
