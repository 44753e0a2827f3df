"""A studio's existing annotations in and out: CSV, ELAN ``.eaf``, Label Studio JSON.

Importing is two requests with the same file: ``inspect`` reads it and says what it holds
(its sources — ELAN tiers, Label Studio annotations, CSV annotators —, its segments, which
labels the project does not have); ``do_import_review`` / ``do_import_gold`` write it, with
the user's mapping of every unknown label to a label of the project. A label is never
created by an import: an unknown label without a mapping refuses the whole import.

Imported into a review, the review becomes exactly the file's segments: a kept cut on a
segment boundary stays (a pending candidate there counts as accepted), every other kept
cut is deleted, a boundary without a cut gets an inserted one, and each segment takes the
file's label (none in a gap). It is one ``import`` event in the review's audit log, with
every cut and label it changed before and after, so the history and one undo take it back
whole. Imported into gold, it is a gold version saved like an adjudication
(``services.gold.do_save_gold``).

Exports write the same three formats from a review, the gold version or the library.
"""

import json

from django.db import transaction

import motionlib.io.annotations as fmt
from segmentation.errors import Invalid, NotReady
from segmentation.models import Cut, ReviewEvent, SegmentLabel
from segmentation.services.gold import do_save_gold
from segmentation.services.reviews import _write

MAX_FILE_BYTES = 5 * 2**20


class Parsed:
    """An uploaded annotation file read for one capture: every record, the sources, and
    (once a source is chosen, or the file has one) that source's checked spans."""

    def __init__(self, capture, upload, form=None, source=None, unit="seconds"):
        if capture.status != "ready" or not capture.n_frames or not capture.fps:
            raise NotReady(f"capture {capture.pk} is {capture.status}; annotations can be "
                           "imported once it is ready")
        self.name = getattr(upload, "name", None) or "annotations"
        if upload.size > MAX_FILE_BYTES:
            raise Invalid(f"file: {self.name} is {upload.size} bytes; an annotation file may "
                          f"have at most {MAX_FILE_BYTES // 2**20} MB")
        self.format = fmt.format_of(self.name, form)
        self.records = fmt.read_annotations(upload.read(), self.name, self.format,
                                            fps=capture.fps, unit=unit)
        self.sources = fmt.sources_of(self.records)
        self.source = source if source is not None or len(self.sources) > 1 else None
        self.spans, self.other_takes = None, 0
        if source is not None or len(self.sources) <= 1:
            chosen = fmt.select(self.records, take=capture.name, source=source, name=self.name)
            self.spans = fmt.check_spans(chosen, n_frames=capture.n_frames, name=self.name)
            self.source = chosen[0].source
            # Rows of the same source about other takes (a CSV of a whole session).
            self.other_takes = sum(1 for r in self.records if r.source == self.source) - len(chosen)


def label_summary(project, spans):
    """``[{"name", "count", "known", "suggestion"}]`` of the labels of ``spans`` in file
    order: ``known`` when the project has the label in use; else ``suggestion`` is the label
    in use that differs only in case and spaces, if any."""
    in_use = dict(project.labels.filter(retired=False).values_list("name", "name"))
    folded = {_fold(name): name for name in in_use}
    counts = {}
    for span in spans:
        if span.label is not None:
            counts[span.label] = counts.get(span.label, 0) + 1
    return [{"name": name, "count": count, "known": name in in_use,
             "suggestion": None if name in in_use else folded.get(_fold(name))}
            for name, count in counts.items()]


def _fold(name):
    return " ".join(name.split()).casefold()


def inspect(capture, parsed):
    """What an import of ``parsed`` into ``capture`` would do, for the import dialog."""
    spans = parsed.spans or []
    return {
        "file": parsed.name, "format": parsed.format, "sources": parsed.sources,
        "source": parsed.source, "chosen": parsed.spans is not None,
        "other_takes": parsed.other_takes,
        "segments": [{"start": s.start, "stop": s.stop, "label": s.label, "where": s.where}
                     for s in spans],
        "labels": label_summary(capture.project, spans),
        "project_labels": list(capture.project.labels.filter(retired=False)
                               .values_list("name", flat=True)),
    }


def parse_mapping(text):
    """The ``mapping`` field: a JSON object of file label -> project label (may be empty)."""
    if text in (None, ""):
        return {}
    try:
        mapping = json.loads(text) if isinstance(text, str) else text
    except ValueError:
        raise Invalid("mapping: must be a JSON object of file label to project label") from None
    if not isinstance(mapping, dict) or not all(
            isinstance(k, str) and isinstance(v, str) for k, v in mapping.items()):
        raise Invalid("mapping: must be a JSON object of file label to project label, "
                      f"got {str(text)[:80]!r}")
    return mapping


def mapped_spans(capture, parsed, mapping):
    """The spans of ``parsed`` with every label a label in use of the project: known as they
    are, unknown through ``mapping``. Invalid lists the unknown labels left unmapped and the
    mappings to no label in use."""
    if parsed.spans is None:
        raise Invalid(f"source: {parsed.name} holds {len(parsed.sources)} sources "
                      f"({', '.join(map(repr, parsed.sources[:10]))}); choose one")
    in_use = set(capture.project.labels.filter(retired=False).values_list("name", flat=True))
    summary = label_summary(capture.project, parsed.spans)
    unknown = [x["name"] for x in summary if not x["known"]]
    unmapped = [name for name in unknown if name not in mapping]
    if unmapped:
        raise Invalid(f"labels: {', '.join(map(repr, unmapped[:20]))} "
                      f"{'is not a label' if len(unmapped) == 1 else 'are not labels'} of this "
                      f"project; map each to one of ({', '.join(sorted(in_use))}) or change the "
                      "file — an import creates no label")
    wrong = [f"{k!r} -> {v!r}" for k, v in mapping.items() if k in unknown and v not in in_use]
    if wrong:
        raise Invalid(f"mapping: {', '.join(wrong[:20])}: map to a label in use of this project "
                      f"({', '.join(sorted(in_use))})")
    return [fmt.Span(s.start, s.stop, mapping.get(s.label, s.label) if s.label else None, s.where)
            for s in parsed.spans]


def plan(spans, n_frames):
    """``(cuts, labels)``: the cut frames the spans' boundaries make (inside the take, in
    order), and one label (or None) per segment between them; a gap has none."""
    cuts = sorted({f for s in spans for f in (s.start, s.stop)} - {0, n_frames})
    by_start = {s.start: s.label for s in spans}
    labels = [by_start.get(start) for start in [0, *cuts]]
    return cuts, labels


def do_import_review(review, user, parsed, mapping, version):
    """Make ``review`` the file's segments, as one ``import`` event; StaleVersion if the
    caller's ``version`` is old, ReviewClosed if the review was submitted."""
    spans = mapped_spans(review.capture, parsed, mapping)
    cuts, labels = plan(spans, review.capture.n_frames)
    with transaction.atomic():
        _write(review, version)
        before, after, starts = _apply_cuts(review, cuts)
        label_before, label_after = _apply_labels(review, [None, *starts], labels)
        ReviewEvent.objects.create(
            review=review, user=user, action="import",
            before={"cuts": before, "labels": label_before},
            after={"cuts": after, "labels": label_after, "file": parsed.name,
                   "format": parsed.format, "source": parsed.source, "segments": len(spans),
                   "mapping": {k: v for k, v in mapping.items()
                               if any(s.label == k for s in parsed.spans)}})
    return review


def _apply_cuts(review, frames):
    """Cuts of ``review`` on exactly ``frames``; ``(before, after, start cut ids)`` where
    before/after are ``[id, frame, fate]`` of each changed cut (a new cut was "deleted")."""
    wanted = set(frames)
    cuts = list(review.cuts.all())
    kept = {c.frame: c for c in cuts if c.fate != "deleted"}
    before, changed = [], []
    for cut in cuts:
        state = [cut.pk, cut.frame, cut.fate]
        if cut.fate != "deleted" and cut.frame not in wanted:
            cut.fate = "deleted"
        elif cut.fate == "pending" and cut.frame in wanted:
            cut.fate = "accepted"
        elif (cut.fate == "deleted" and cut.frame in wanted and cut.frame not in kept
              and cut.origin == "candidate" and cut.frame == cut.candidate_frame):
            cut.fate, kept[cut.frame] = "accepted", cut  # the detector's own cut, taken back
        else:
            continue
        before.append(state)
        changed.append(cut)
    Cut.objects.bulk_update(changed, ["fate"])
    new = Cut.objects.bulk_create(Cut(review=review, origin="inserted", fate="accepted", frame=f)
                                  for f in frames if f not in kept)
    for cut in new:
        kept[cut.frame] = cut
        before.append([cut.pk, cut.frame, "deleted"])
    after = [[c.pk, c.frame, c.fate] for c in [*changed, *new]]
    return before, after, [kept[f].pk for f in frames]


def _apply_labels(review, start_cuts, names):
    """Each segment (by the cut that starts it) takes its label; ``(before, after)`` as
    ``[start cut id, label name]`` of each segment whose label changed."""
    ids = dict(review.capture.project.labels.values_list("name", "pk"))
    rows = {row.cut_id: row for row in review.segment_labels.select_related("label")}
    before, after = [], []
    for cut_id, name in zip(start_cuts, names, strict=True):
        row = rows.get(cut_id)
        old = row.label.name if row is not None and row.label is not None else None
        if old == name:
            continue
        if row is None:
            SegmentLabel.objects.create(review=review, cut_id=cut_id, label_id=ids.get(name))
        else:
            SegmentLabel.objects.filter(pk=row.pk).update(label_id=ids.get(name))
        before.append([cut_id, old])
        after.append([cut_id, name])
    return before, after


def do_import_gold(capture, user, parsed, mapping, version):
    """Save the file's segments as the capture's gold version (``do_save_gold``: a
    reviewer's or admin's, at least one submitted review, ``version`` the one seen)."""
    spans = mapped_spans(capture, parsed, mapping)
    cuts, labels = plan(spans, capture.n_frames)
    return do_save_gold(capture, user, cuts, labels, version)
