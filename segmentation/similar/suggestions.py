"""Label suggestions for the unlabelled segments of a review, computed off the request path.

A segment's suggestion is the label with most votes among the ``NEIGHBOURS`` library
segments that move most like it, each vote weighted by 1 / distance². The pool is the
project's library segments of *other* captures that the review's annotator may see
(``LibrarySegment.visible_to``: gold and their own for an annotator, everything for a
reviewer or admin): another annotator's labels would show them what they may not see
and bias the independent annotation that agreement assumes.

One suggestion costs a DTW ranking; a one-hour take has thousands of segments. So no
review request computes them: ``…/review/suggestions/`` reads stored ``LabelSuggestion``
rows and, for the spans that have none, sends the ``suggest`` job once
(``SuggestionRequest``); the worker stores them in batches, and the page polls. A row is
keyed by its span and by the pool and its state (``pool_key``), so an edit needs new
suggestions only for the spans it creates, a change to the pool makes the old rows stale
without any request deleting them, and annotators with the same pool (every annotator
who has no segment of their own in the library sees gold only) share the rows.
"""

import logging
import os
import random
import sys
import threading
from collections import Counter
from datetime import timedelta

import numpy as np
from django.db import connection, transaction
from django.db.models import Count, F, Max, Q
from django.utils import timezone

from motionlib import similarity
from segmentation import workers
from segmentation.errors import internal_error
from segmentation.models import (
    Capture,
    Label,
    LabelSuggestion,
    LibrarySegment,
    Review,
    SuggestionRequest,
)
from segmentation.similar import proposals
from segmentation.similar.descriptors import Describer, load_descriptors, profile_pool, same_kind
from segmentation.similar.search import SHORTLIST, SIMILAR_POOL

log = logging.getLogger(__name__)

NEIGHBOURS = 5
# Spans computed and stored together: the page sees the first ones after one batch.
BATCH = 100
# A job that has neither finished nor reported progress for this long is taken as lost.
ASK_AGAIN_AFTER = timedelta(minutes=2)
# A job that failed is not sent again for this long: the same input would fail again, and a
# page asking every few seconds must not turn one failure into a loop.
RETRY_FAILED_AFTER = timedelta(hours=1)
# Nice value added to the thread computing suggestions: the worker shares the machine
# with the web server (the embedded default), and a page request should come first.
LOW_PRIORITY = 10


def pool(capture, annotator):
    """The library segments suggestions for ``annotator``'s review of ``capture`` draw on:
    described as ``capture`` is (``descriptors.same_kind``), and none of a retired label,
    which could not be applied (retiring or restoring one changes the pool's state, so
    stored suggestions follow)."""
    return (LibrarySegment.objects.visible_to(annotator).preferred()
            .filter(same_kind(capture), project_id=capture.project_id, profile__isnull=False,
                    label__retired=False)
            .exclude(capture_id=capture.pk))


def pool_key(capture, annotator):
    """``"<pool>:<rows>:<newest id>"`` naming the pool and its state, or None when it is
    empty. The pool is ``all`` (a reviewer or admin), ``gold`` (an annotator with no
    segment of their own in it) or ``own<user id>``; annotators with the same key draw on
    the very same segments.

    The library replaces a capture's rows when a review is submitted or gold saved (new
    ids) and deletes them with their capture (fewer rows), so the state changes.
    """
    if not capture.project.can_see_all_reviews(annotator):
        found = pool(capture, annotator).aggregate(
            n=Count("id"), newest=Max("id"), own=Count("id", filter=Q(annotator=annotator)))
        name = f"own{annotator.pk}" if found["own"] else "gold"
    else:
        found = pool(capture, annotator).aggregate(n=Count("id"), newest=Max("id"))
        name = "all"
    return f"{name}:{found['n']}:{found['newest']}" if found["n"] else None


def unlabelled_spans(capture, annotator):
    """``[(start, stop)]`` of the unlabelled segments of the annotator's review, or of the
    review they would start (the latest finished run's candidates) if they have none."""
    review = Review.objects.filter(capture=capture, annotator=annotator).first()
    if review is not None:
        rows = review.segments()
    else:
        run = capture.latest_finished_run()
        frames = sorted({c["frame"] for c in run.candidates}) if run else []
        bounds = [0, *frames, capture.n_frames or 0]
        rows = [(i, a, b, None) for i, (a, b) in enumerate(zip(bounds[:-1], bounds[1:], strict=True))]
    return [(start, stop) for _, start, stop, label in rows if label is None and stop > start]


def stored(capture, key, spans):
    """{(start, stop): label name or None} of ``spans`` stored for the pool ``key``."""
    rows = LabelSuggestion.objects.filter(capture=capture, pool=key)
    found = dict(((s, e), name) for s, e, name in rows.values_list("start", "stop", "label__name"))
    return {span: found[span] for span in spans if span in found}


def for_review(capture, annotator):
    """What the review page shows: ``{"pending", "suggestions": [{"start", "stop", "label",
    "probability", "proposed"}]}`` for the unlabelled segments, sending the job for any span
    not computed yet.

    A span's proposed label (``proposals``, with its probability) comes first when it is at
    least ``proposals.MIN_PROBABILITY`` likely; else the label the library suggests (``probability`` None, ``proposed`` false). An annotator's
    proposals are their own pool's (``proposals.propose_spans``, computed by the job); a
    reviewer's or admin's are the detection run's (``proposed``), learnt from all reviews,
    which they may see. ``pending`` is true while some span still waits for the worker.
    """
    spans = unlabelled_spans(capture, annotator)
    key = pool_key(capture, annotator) if spans else None
    found = stored(capture, key, spans) if key else {}
    staff = capture.project.can_see_all_reviews(annotator)
    if staff:
        offered = proposed(capture, spans)
        missing = len(found) < len(spans)
    else:
        offered = stored_proposals(capture, key, spans) if key else {}
        missing = len(found) < len(spans) or len(offered) < len(spans)
    pending = bool(key) and missing
    if pending:
        pending = ask(capture, annotator) or not recently_failed(capture, annotator)
    out = []
    for span in sorted(set(found) | set(offered)):
        label, probability = offered.get(span) or (None, None)
        if label is not None and (probability or 0.0) >= proposals.MIN_PROBABILITY:
            out.append({"start": span[0], "stop": span[1], "label": label,
                        "probability": probability, "proposed": True})
        else:
            out.append({"start": span[0], "stop": span[1], "label": found.get(span),
                        "probability": None, "proposed": False})
    return {"pending": pending, "suggestions": out}


def stored_proposals(capture, key, spans):
    """{(start, stop): (label name or None, probability or None)} of ``spans`` proposed
    for the pool ``key`` (rows of the pool ``proposals.PREFIX + key``)."""
    rows = LabelSuggestion.objects.filter(capture=capture, pool=proposals.PREFIX + key)
    # A label retired since is proposed no more.
    found = {(s, e): (None, None) if retired else (name, p) for s, e, name, retired, p in
             rows.values_list("start", "stop", "label__name", "label__retired", "probability")}
    return {span: found[span] for span in spans if span in found}


def proposed(capture, spans):
    """``{(start, stop): (label name, probability)}`` of the latest finished run's proposals
    (``DetectionRun.proposals``) for the ``spans`` that are still one of its segments;
    labels retired since are left out."""
    run = capture.latest_finished_run()
    if run is None or not run.proposals:
        return {}
    frames = sorted({c["frame"] for c in run.candidates})
    bounds = [0, *frames, capture.n_frames or 0]
    names = dict(Label.objects.filter(project_id=capture.project_id, retired=False)
                 .values_list("id", "name"))
    wanted = set(spans)
    return {(a, b): (names[p["label"]], p.get("probability"))
            for a, b, p in zip(bounds[:-1], bounds[1:], run.proposals, strict=False)
            if (a, b) in wanted and p["label"] in names}


def ask(capture, annotator):
    """Send the ``suggest`` job unless one is on its way or the last one failed less than
    RETRY_FAILED_AFTER ago; True if it was sent."""
    request, _ = SuggestionRequest.objects.get_or_create(capture=capture, annotator=annotator)
    now = timezone.now()
    idle = Q(asked_at__isnull=True) | Q(done_at__gte=F("asked_at")) | Q(asked_at__lt=now - ASK_AGAIN_AFTER)
    idle &= Q(failed_at__isnull=True) | Q(failed_at__lt=now - RETRY_FAILED_AFTER)
    # One conditional UPDATE claims the ask: 0 rows means a job is on its way.
    claimed = SuggestionRequest.objects.filter(idle, pk=request.pk).update(asked_at=now, done_at=None)
    if claimed:
        transaction.on_commit(lambda: _send(capture.pk, annotator.pk))
    return bool(claimed)


def _send(capture_id, annotator_id):
    workers.send("suggest", capture_id, annotator_id,
              then="the next look at the page asks again once the request counts as lost")


def fill(capture, annotator):
    """Compute and store the suggestions the annotator's review is missing (the job).

    Rows of an older state of the same pool are deleted first. Jobs of annotators who
    share a pool may run at once: each takes the spans in its own order and skips those
    another job has stored meanwhile. Returns the number of spans computed.
    """
    key = pool_key(capture, annotator)
    if key is not None:
        name = key.split(":")[0]
        for prefix in ("", proposals.PREFIX):
            (LabelSuggestion.objects.filter(capture=capture, pool__startswith=f"{prefix}{name}:")
             .exclude(pool=prefix + key).delete())
    spans = unlabelled_spans(capture, annotator) if key else []
    if spans and not capture.project.can_see_all_reviews(annotator):
        fill_proposals(capture, annotator, key, spans)
    have = stored(capture, key, spans) if key else {}
    missing = [span for span in spans if span not in have]
    random.Random(annotator.pk).shuffle(missing)
    request = SuggestionRequest.objects.filter(capture=capture, annotator=annotator)
    suggester, computed = None, 0
    for i in range(0, len(missing), BATCH):
        done = stored(capture, key, missing[i:i + BATCH]) if i else {}
        batch = sorted(span for span in missing[i:i + BATCH] if span not in done)
        if not batch:
            continue
        # Computing reads only; the writes stay at normal priority, so a low-priority
        # thread never holds the database's write lock (SQLite) while others wait on it.
        suggester = suggester or at_low_priority(Suggester, capture, annotator)
        labels = at_low_priority(suggester.labels, batch)
        LabelSuggestion.objects.bulk_create(
            [LabelSuggestion(capture=capture, pool=key, start=s, stop=e, label_id=label)
             for (s, e), label in zip(batch, labels, strict=True)],
            ignore_conflicts=True)
        computed += len(batch)
        # Progress: a job still working is not taken as lost.
        request.update(asked_at=timezone.now())
    request.update(done_at=timezone.now())
    return computed


def fill_proposals(capture, annotator, key, spans):
    """Store the annotator's own proposals (``proposals.propose_spans`` over their pool)
    for the ``spans`` that have none for the pool ``key``. One fit serves all the spans:
    a 60-minute take's take as many seconds as its pool's fit and one posterior."""
    have = stored_proposals(capture, key, spans)
    missing = sorted(span for span in spans if span not in have)
    if not missing:
        return
    found = at_low_priority(proposals.propose_spans, capture, pool(capture, annotator), missing)
    LabelSuggestion.objects.bulk_create(
        [LabelSuggestion(capture=capture, pool=proposals.PREFIX + key, start=s, stop=e,
                         label_id=label, probability=p)
         for (s, e), (label, p) in zip(missing, found, strict=True)],
        ignore_conflicts=True)


def fill_by_id(capture_id, annotator_id):
    """``fill`` for the job (ids in); 0 if either row is gone.

    Any error (a MemoryError too) fails the job once: logged with a reference, stored on
    the request's row, and not asked again for RETRY_FAILED_AFTER. It never reaches the
    worker, whose main process a MemoryError would end, its message going back to the
    queue to end the next one.
    """
    from django.contrib.auth import get_user_model

    capture = Capture.objects.filter(pk=capture_id).first()
    annotator = get_user_model().objects.filter(pk=annotator_id).first()
    if capture is None or annotator is None:
        return 0  # deleted since the job was sent
    try:
        return fill(capture, annotator)
    except Exception:  # a MemoryError is one: the reason for this guard
        reference = internal_error(f"label suggestions for capture {capture_id}", log)
        failed(capture_id, annotator_id, f"label suggestions failed (reference {reference})")
        return 0


def failed(capture_id, annotator_id, error):
    """Store on the request's row that its job failed, and why."""
    now = timezone.now()
    SuggestionRequest.objects.filter(capture_id=capture_id, annotator_id=annotator_id).update(
        done_at=now, failed_at=now, error=error[:2000])


def recently_failed(capture, annotator):
    """True when the last job for this review failed less than RETRY_FAILED_AFTER ago."""
    return SuggestionRequest.objects.filter(
        capture=capture, annotator=annotator,
        failed_at__gte=timezone.now() - RETRY_FAILED_AFTER).exists()


def at_low_priority(work, *args):
    """``work(*args)`` run in a thread whose nice value is ``LOW_PRIORITY`` higher.

    Linux keeps a nice value per thread, so the priority ends with the thread and the
    worker's next job (ingest, detection) runs at its usual priority; a process cannot
    lower its nice value again without privileges. Elsewhere, or inside a transaction
    (which another thread's connection could not see, e.g. in tests), it runs here.
    """
    if sys.platform != "linux" or connection.in_atomic_block:
        return work(*args)
    outcome = {}

    def run():
        tid = threading.get_native_id()
        try:
            os.setpriority(os.PRIO_PROCESS, tid, os.getpriority(os.PRIO_PROCESS, tid) + LOW_PRIORITY)
            outcome["value"] = work(*args)
        except BaseException as exc:  # handed to the job's own thread below
            outcome["error"] = exc
        finally:
            connection.close()  # this thread's own connection

    thread = threading.Thread(target=run, name="suggest", daemon=True)
    thread.start()
    thread.join()
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]


class Suggester:
    """Labels for spans of one capture from one annotator's pool; loads the capture's
    positions and the pool's profiles once for all the spans of a job."""

    def __init__(self, capture, annotator):
        self.capture = capture
        self.describe = None
        try:
            self.describe = Describer(capture)
        except (OSError, ValueError) as exc:
            log.warning("no label suggestions for capture %s: %s", capture.pk, exc)
        self.ids, self.profiles, self.names = [], None, {}
        if self.usable:
            rows = list(pool(capture, annotator).order_by("-is_gold", "-id")
                        .values_list("id", "profile", "label_id")[:SIMILAR_POOL])
            self.names = {pk: name for pk, _, name in rows}
            self.rows = [(pk, blob) for pk, blob, _ in rows]

    @property
    def usable(self):
        return self.describe is not None and self.describe.usable

    def labels(self, spans):
        """A label id or None for each ``(start, stop)``."""
        if not self.usable or not self.names:
            return [None] * len(spans)
        queries = [self.describe(s, e) for s, e in spans]
        if self.profiles is None:
            self.ids, profiles = profile_pool(self.rows, queries[0].shape[1])
            self.profiles = profiles.astype(float)
        shortlists = [[self.ids[i] for i in similarity.shortlist_by_profile(q, self.profiles, SHORTLIST)]
                      for q in queries]
        union = sorted({pk for short in shortlists for pk in short})
        full = dict(zip(union, load_descriptors(union), strict=True))
        return [vote(q, short, full, self.names) for q, short in zip(queries, shortlists, strict=True)]


def vote(query, short, full, names):
    """The label with most votes among the nearest neighbours, a vote weighing 1 / d²:
    with a small library a plain majority would name whichever label is most common
    rather than the one that moves alike."""
    order, distances = similarity.rank_similar(
        query, np.stack([full[pk] for pk in short]), k=min(NEIGHBOURS, len(short)),
        shortlist=len(short))
    votes = Counter()
    for i, d in zip(order, distances, strict=True):
        votes[names[short[i]]] += 1.0 / (d * d + 1e-9)
    return votes.most_common(1)[0][0]
