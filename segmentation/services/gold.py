"""Gold versions: a reviewer's adjudicated cuts and labels of a capture."""

from django.db import transaction
from django.utils import timezone

from segmentation.errors import Invalid, StaleGold
from segmentation.models import Adjudication
from segmentation.services.adaptation import on_examples_changed
from segmentation.services.attributes import store_gold_values
from segmentation.services.library import refresh_capture_library


def check_gold(capture, cuts, labels):
    """Validated (cuts, labels) of a gold version, labels still as sent (names or null);
    Invalid names the bad value."""
    if not isinstance(cuts, list) or not all(isinstance(c, int) and not isinstance(c, bool)
                                             for c in cuts):
        raise Invalid(f"cuts: must be a list of frame numbers, got {cuts!r}")
    for i, frame in enumerate(cuts):
        capture.check_cut_frame(frame, "cuts", f"cut {i}")
        if i and frame <= cuts[i - 1]:
            raise Invalid(f"cuts: cut {i} at frame {frame} is not after the previous cut "
                          f"({cuts[i - 1]}); send cuts in increasing frame order")
    if not isinstance(labels, list) or len(labels) != len(cuts) + 1:
        raise Invalid(f"labels: expected {len(cuts) + 1} labels (one per segment), "
                      f"got {len(labels) if isinstance(labels, list) else repr(labels)}")
    return cuts, labels


def carried_labels(capture, current):
    """``{(start, stop): {label ids}}``: the labels segments already carry, in the current
    gold version and in the capture's submitted reviews."""
    carried = {}
    spans = list(current.label_segments()) if current else []
    for review in capture.reviews.filter(status="submitted"):
        spans += [(start, stop, x) for _, start, stop, x in review.segments(label="label_id")]
    for start, stop, label_id in spans:
        if label_id is not None:
            carried.setdefault((start, stop), set()).add(label_id)
    return carried


def gold_label_ids(capture, cuts, names, current):
    """The label ids of a gold version's segments, from the labels' current names.

    A retired label is not offered for new segments, but a segment that already carries
    it (the same span with the same label, in the current gold version or a submitted
    review) keeps it: re-saving gold unchanged after a retire is not refused.
    """
    labels = {label.name: label for label in capture.project.labels.all()}
    carried = carried_labels(capture, current)
    bounds = [0, *cuts, capture.n_frames]
    ids = []
    for i, name in enumerate(names):
        label = labels.get(name) if name is not None else None
        if name is not None and label is None:
            in_use = sorted(x.name for x in labels.values() if not x.retired)
            raise Invalid(f"labels: segment {i} has label {name!r}, which is not a label of "
                          f"this project ({', '.join(in_use)})")
        if label is not None and label.retired and label.pk not in carried.get(
                (bounds[i], bounds[i + 1]), ()):
            raise Invalid(f"labels: segment {i} has label {name!r}, which is retired; a retired "
                          "label stays only on segments that already carry it, pick a label in use")
        ids.append(label.pk if label is not None else None)
    return ids


def do_save_gold(capture, user, cuts, labels, version, source_review=None, attributes=None):
    """Create or replace the capture's gold version and rebuild its library rows.

    ``labels`` are the segments' label names (or null), stored as label ids.
    ``version`` is the gold version the reviewer started from (0 when there was none);
    anything else than the current version is refused with ``StaleGold``. ``attributes``:
    the segments' attribute values (``services.attributes.store_gold_values``; when
    omitted they travel with unchanged segments and from ``source_review``).
    """
    cuts, labels = check_gold(capture, cuts, labels)
    if not capture.reviews.filter(status="submitted").exists():
        raise Invalid("capture: a gold version needs at least one submitted review")
    if source_review is not None and source_review.capture_id != capture.pk:
        raise Invalid(f"source_review: review {source_review.pk} is not of this capture")
    with transaction.atomic():
        current = Adjudication.objects.select_for_update().filter(capture=capture).first()
        if (current.version if current else 0) != version:
            raise StaleGold(current) if current else Invalid(
                f"version: there is no gold version yet; send 0, got {version}")
        label_ids = gold_label_ids(capture, cuts, labels, current)
        previous = [(start, stop) for start, stop, _ in current.label_segments()] if current else []
        store_gold_values(capture, previous, cuts, attributes, source_review)
        gold = current or Adjudication(capture=capture, version=0)
        gold.adjudicator, gold.source_review = user, source_review
        gold.cuts, gold.labels = cuts, label_ids
        gold.version += 1
        gold.updated_at = timezone.now()
        gold.save()
        refresh_capture_library(capture)
        on_examples_changed(capture.project_id)
    return gold
