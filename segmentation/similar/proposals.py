"""Proposed labels: what a frame model (``motionlib.labelling``) finds most likely in each
segment of a review, learnt only from what the viewer may see.

A detection run's own proposals (``DetectionRun.proposals``) come from the project's frame
model, learnt from the consensus of every annotator's reviews: a reviewer or admin, who
sees all reviews, is shown those. An annotator is not: the independent annotation that
agreement measures assumes that nobody sees another annotator's labels, and a model learnt
from them would show them. An annotator's proposals come from a frame model learnt from
their own pool alone (``suggestions.pool``: gold segments, else their own submitted
reviews' segments, of the project's other captures), fitted in the ``suggest`` job when
their review is opened and stored as ``LabelSuggestion`` rows of the pool ``p:<pool key>``
with the proposal's probability.

It stays cheap for long takes: a take's frame descriptors (``labelling.frame_example``)
never change, so each capture's are stored once beside its parsed take and a fit reads
them instead of the takes; fitting is a PCA and a k-d tree over at most 40 000 points.

Every fitted model passes a held-out check first (``held_out``): each reviewed take is
proposed by the model without that take's own points, and the model is used only if its
proposals match more of the reviewed frames than the best constant proposal
(unlabelled everywhere, or the commonest label everywhere) would.
"""

import bisect
import dataclasses
import logging
from collections import defaultdict

import numpy as np

from motionlib import labelling
from segmentation.files import takecache
from segmentation.files.storage import read_take
from segmentation.models import Capture, Label

log = logging.getLogger(__name__)

# Reviewed takes the held-out check scores (most recent first): each costs a tree query.
HELD_OUT_TAKES = 10
# Fewer reviewed takes than this leave nothing to hold out: no proposal.
MIN_TAKES = 2
# A proposal less likely than this is not shown (the library's suggestion is, if any): the
# frame model's nearest references then disagree, and on the vMCI point takes, whose
# one-second actions its 5 Hz windows blur, every proposal below it was wrong while the
# library's suggestions were right (tests/segmentation/test_point_takes.py).
MIN_PROBABILITY = 0.6
FRAMES_KEY = "frames-v1"
PREFIX = "p:"


def frames_of(capture, segments=(), read=None):
    """The capture as a ``labelling.FrameExample`` with ``segments``; its descriptors read
    from storage when stored, else computed from its take (``read(capture)``, by default
    the parsed-take cache), then stored."""
    stored = takecache.StoredStudies(Capture._meta.get_field("original").storage)
    name = takecache.example_key(capture) + "-frames"
    arrays = stored.load(name, FRAMES_KEY)
    if arrays is None:
        take = read(capture) if read else takecache.read_cached(capture, read_take)
        example = labelling.frame_example(take, [])
        stored.save(name, FRAMES_KEY, {"samples": example.samples,
                                       "descriptors": example.descriptors.astype(np.float32)})
        return dataclasses.replace(example, segments=list(segments))
    return labelling.FrameExample(arrays["samples"].astype(np.int64),
                                  arrays["descriptors"].astype(float),
                                  int(capture.n_frames or 0), float(capture.fps), list(segments))


# ---- the held-out check ------------------------------------------------------------------


@dataclasses.dataclass
class Check:
    """A frame model's held-out label accuracy against the best constant proposal, both
    as the share of reviewed frames proposed their reviewed label (or "unlabelled")."""

    takes: int = 0
    frames: int = 0
    right: int = 0
    constant: float = 0.0

    @property
    def accuracy(self):
        return self.right / self.frames if self.frames else 0.0

    @property
    def passed(self):
        return self.takes >= 1 and self.accuracy > self.constant + 1e-9


def held_out(model, examples):
    """``Check`` of ``model`` (fitted on ``examples``, in that order): each of the last
    HELD_OUT_TAKES examples proposed by the model without its own points, its reviewed
    segments as the cuts."""
    check = Check()
    counts = defaultdict(int)
    for i in range(len(examples) - 1, max(-1, len(examples) - 1 - HELD_OUT_TAKES), -1):
        e = examples[i]
        bounds = sorted(_bounds(e.segments, e.n_frames))
        post = labelling.posterior(model, e, exclude=i)
        truth = _truth(e.segments, bounds)
        for (a, b), (label, _p), true in zip(zip(bounds[:-1], bounds[1:], strict=True),
                                             labelling.propose(model, post, bounds[1:-1]),
                                             truth, strict=True):
            check.frames += b - a
            check.right += (b - a) if (label or "") == true else 0
            counts[true] += b - a
        check.takes += 1
    check.constant = max(counts.values()) / check.frames if check.frames else 0.0
    return check


def _bounds(segments, n_frames):
    """Every frame where a reviewed segment starts or ends, with 0 and ``n_frames``."""
    found = {0, n_frames}
    for a, b, _label in segments:
        found.update((min(max(a, 0), n_frames), min(max(b, 0), n_frames)))
    return found


def _truth(segments, bounds):
    """The reviewed label ("" for none) of each stretch between ``bounds``, which hold every
    segment's start and end: a stretch lies within one segment or between segments, so its
    first frame's label is its own."""
    labelled = sorted((a, b, str(lab)) for a, b, lab in segments if lab and b > a)
    starts = [a for a, _b, _lab in labelled]
    out = []
    for a in bounds[:-1]:
        i = bisect.bisect_right(starts, a) - 1
        out.append(labelled[i][2] if i >= 0 and a < labelled[i][1] else "")
    return out


def checked_fit(examples):
    """``labelling.fit_frame_model(examples)`` if it passes the held-out check, else None
    (also with fewer than MIN_TAKES examples: nothing to hold out)."""
    if len(examples) < MIN_TAKES:
        return None
    model = labelling.fit_frame_model(examples)
    if model is None:
        return None
    check = held_out(model, examples)
    if not check.passed:
        log.info("frame model refused: held-out label accuracy %.3f on %d takes, a constant "
                 "proposal %.3f", check.accuracy, check.takes, check.constant)
        return None
    return model


# ---- an annotator's own proposals ---------------------------------------------------------


def pool_examples(segments):
    """``[FrameExample]`` of a pool's library segments: one per reviewed take (a capture's
    gold, else each review of it), oldest first, labels by id."""
    takes = defaultdict(list)
    captures = {}
    for row in segments.select_related("capture").order_by("capture_id", "start"):
        takes[(row.capture_id, "gold" if row.is_gold else row.review_id)].append(
            (row.start, row.stop, str(row.label_id)))
        captures[row.capture_id] = row.capture
    out = []
    for (capture_id, _whose), rows in sorted(takes.items(), key=lambda kv: (kv[0][0], str(kv[0][1]))):
        try:
            out.append(frames_of(captures[capture_id], rows))
        except (OSError, ValueError) as exc:
            log.warning("capture %s left out of the proposals' pool: %s", capture_id, exc)
    return out


def propose_spans(capture, pool, spans):
    """``[(label id or None, probability or None)]`` for each ``(start, stop)`` of a review
    of ``capture``, from the checked frame model of the library segments ``pool`` (an
    annotator's own: ``suggestions.pool``); all None when the pool makes no model or its
    model fails the held-out check."""
    if not spans:
        return []
    model = checked_fit(pool_examples(pool))
    if model is None:
        return [(None, None)] * len(spans)
    post = labelling.posterior(model, frames_of(capture))
    alive = set(Label.objects.filter(project_id=capture.project_id, retired=False)
                .values_list("id", flat=True))
    out = []
    for start, stop in spans:
        (name, p), = labelling.propose(model, post[start:max(stop, start + 1)], [])
        label = int(name) if name else None
        out.append((label, p) if label in alive else (None, None))
    return out
