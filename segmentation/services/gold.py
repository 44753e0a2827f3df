"""Gold versions: a reviewer's adjudicated cuts and labels of a capture."""

from django.db import transaction
from django.utils import timezone

from segmentation.errors import Invalid, StaleGold
from segmentation.models import Adjudication
from segmentation.services.adaptation import on_examples_changed
from segmentation.services.library import refresh_capture_library


def check_gold(capture, cuts, labels):
    """Validated (cuts, labels) of a gold version; Invalid names the bad value."""
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
    known = set(capture.project.labels.values_list("name", flat=True))
    for i, name in enumerate(labels):
        if name is not None and name not in known:
            raise Invalid(f"labels: segment {i} has label {name!r}, which is not a label of "
                          f"this project ({', '.join(sorted(known))})")
    return cuts, labels


def do_save_gold(capture, user, cuts, labels, version, source_review=None):
    """Create or replace the capture's gold version and rebuild its library rows.

    ``version`` is the gold version the reviewer started from (0 when there was none);
    anything else than the current version is refused with ``StaleGold``.
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
        gold = current or Adjudication(capture=capture, version=0)
        gold.adjudicator, gold.source_review = user, source_review
        gold.cuts, gold.labels = cuts, labels
        gold.version += 1
        gold.updated_at = timezone.now()
        gold.save()
        refresh_capture_library(capture)
        on_examples_changed(capture.project_id)
    return gold
