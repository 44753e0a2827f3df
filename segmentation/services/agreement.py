"""Agreement between the submitted reviews of a capture.

The numbers come from ``motionlib.agreement``; this module feeds it the reviews' kept
cuts and labelled segments, names the annotators, and keeps a summary row per capture
(``CaptureAgreement``) so the dashboard (``segmentation.queries.dashboard``) never recomputes
agreement for every capture.
"""

import math

from motionlib.agreement import take_agreement
from segmentation.errors import Invalid
from segmentation.models import CaptureAgreement, Review

DEFAULT_TOLERANCE_S = 0.25


def finite(value):
    """JSON has no NaN: undefined measures are null."""
    return None if value is None or math.isnan(value) else round(float(value), 4)


def submitted_reviews(capture):
    return list(
        Review.objects.filter(capture=capture, status="submitted")
        .select_related("capture", "annotator")
        .prefetch_related("cuts", "segment_labels__label")
        .order_by("id")
    )


def review_cuts(review):
    return sorted(c.frame for c in review.kept_cuts())


def review_segments(review, label="label__name"):
    """``[(start, stop, label name or None)]``, or label ids with ``label="label_id"``."""
    return [(start, stop, x) for _, start, stop, x in review.segments(label=label)]


def compute(capture, reviews, tolerance_s=DEFAULT_TOLERANCE_S, label="label__name"):
    """motionlib's take agreement over ``reviews`` (at least one), labels named by
    ``label`` (see ``review_segments``)."""
    return take_agreement(
        [review_segments(r, label) for r in reviews],
        [review_cuts(r) for r in reviews],
        n_frames=capture.n_frames,
        fps=capture.fps,
        tolerance_s=tolerance_s,
    )


def label_measure(result, n_reviews):
    """Cohen's kappa for a pair, Krippendorff's alpha for more."""
    if n_reviews < 2:
        return None, None
    if n_reviews == 2:
        return "cohen_kappa", result["pairs"][0]["kappa"]
    return "krippendorff_alpha", result["alpha"]


def capture_agreement(capture, tolerance_s=DEFAULT_TOLERANCE_S):
    """The body of ``GET /api/captures/{id}/agreement/``."""
    if tolerance_s < 0 or tolerance_s > 10:
        raise Invalid(f"tolerance: must be between 0 and 10 seconds, got {tolerance_s}")
    reviews = submitted_reviews(capture)
    body = {
        "capture": capture.pk,
        "tolerance_s": tolerance_s,
        "n_reviews": len(reviews),
        "reviews": [
            {"id": r.pk, "annotator": {"id": r.annotator_id, "username": r.annotator.username},
             "cuts": len(review_cuts(r)), "submitted_at": r.submitted_at}
            for r in reviews
        ],
        "pairs": [], "boundary_f1": None, "labels": {"method": None, "value": None},
        "alpha": None, "per_label": [],
    }
    if len(reviews) < 2:
        return body
    result = compute(capture, reviews, tolerance_s)
    method, value = label_measure(result, len(reviews))
    body["pairs"] = [_pair(p, reviews) for p in result["pairs"]]
    body["boundary_f1"] = finite(result["mean_boundary_f1"])
    body["labels"] = {"method": method, "value": finite(value)}
    body["alpha"] = finite(result["alpha"])
    body["per_label"] = [
        {"label": name, "overlap": finite(v["overlap"]), "frames": v["frames"]}
        for name, v in sorted(result["per_label"].items())
    ]
    return body


def _pair(pair, reviews):
    a, b = reviews[pair["a"]], reviews[pair["b"]]
    boundary = pair["boundary"]
    return {
        "a": {"review": a.pk, "annotator": a.annotator.username},
        "b": {"review": b.pk, "annotator": b.annotator.username},
        "precision": finite(boundary["precision"]), "recall": finite(boundary["recall"]),
        "f1": finite(boundary["f1"]), "matched": boundary["matched"],
        "kappa": finite(pair["kappa"]),
    }


def refresh_capture_agreement(capture, reviews=None):
    """Recompute and store the capture's summary row (per label by label id, so that it
    follows a rename); returns it."""
    reviews = submitted_reviews(capture) if reviews is None else reviews
    fields = {"n_reviews": len(reviews), "boundary_f1": None, "label_agreement": None,
              "per_label": {}}
    if len(reviews) >= 2:
        result = compute(capture, reviews, label="label_id")
        fields["boundary_f1"] = finite(result["mean_boundary_f1"])
        fields["label_agreement"] = finite(label_measure(result, len(reviews))[1])
        fields["per_label"] = {
            str(label_id): {"overlap": finite(v["overlap"]), "frames": v["frames"]}
            for label_id, v in result["per_label"].items()
        }
    row, _ = CaptureAgreement.objects.update_or_create(capture=capture, defaults=fields)
    return row
