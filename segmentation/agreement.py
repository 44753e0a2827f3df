"""Agreement between the submitted reviews of a capture, and the project dashboard.

The numbers come from ``motionlib.agreement``; this module feeds it the reviews' kept
cuts and labelled segments, names the annotators, and keeps a summary row per capture
(``CaptureAgreement``) so the dashboard never recomputes agreement for every capture.
"""

import math
from statistics import median

from django.db.models import Count, Q

from motionlib.agreement import take_agreement
from segmentation.models import (
    Adjudication,
    Capture,
    CaptureAgreement,
    LibrarySegment,
    Review,
    ReviewEvent,
)

DEFAULT_TOLERANCE_S = 0.25
EDIT_ACTIONS = ("accept", "delete", "reset", "move", "insert", "label")
STATES = ("unreviewed", "in_review", "agreed", "adjudicated")


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


def review_segments(review):
    return [(start, stop, label) for _, start, stop, label in review.segments()]


def compute(capture, reviews, tolerance_s=DEFAULT_TOLERANCE_S):
    """motionlib's take agreement over ``reviews`` (at least one)."""
    return take_agreement(
        [review_segments(r) for r in reviews],
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
        raise ValueError(f"tolerance: must be between 0 and 10 seconds, got {tolerance_s}")
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
    """Recompute and store the capture's summary row; returns it."""
    reviews = submitted_reviews(capture) if reviews is None else reviews
    fields = {"n_reviews": len(reviews), "boundary_f1": None, "label_agreement": None,
              "per_label": {}}
    if len(reviews) >= 2:
        result = compute(capture, reviews)
        fields["boundary_f1"] = finite(result["mean_boundary_f1"])
        fields["label_agreement"] = finite(label_measure(result, len(reviews))[1])
        fields["per_label"] = {
            name: {"overlap": finite(v["overlap"]), "frames": v["frames"]}
            for name, v in result["per_label"].items()
        }
    row, _ = CaptureAgreement.objects.update_or_create(capture=capture, defaults=fields)
    return row


def capture_state(has_reviews, has_gold, summary):
    """unreviewed / in_review / agreed / adjudicated."""
    if has_gold:
        return "adjudicated"
    if summary is not None and summary.agreed:
        return "agreed"
    return "in_review" if has_reviews else "unreviewed"


def dashboard(project):
    """The body of ``GET /api/projects/{id}/dashboard/``: states, throughput, labels."""
    captures = (
        Capture.objects.filter(project=project, status="ready")
        .annotate(n_reviews=Count("reviews"),
                  n_submitted=Count("reviews", filter=Q(reviews__status="submitted")))
        .order_by("id")
    )
    summaries = {a.capture_id: a for a in CaptureAgreement.objects.filter(capture__project=project)}
    gold = set(Adjudication.objects.filter(capture__project=project).values_list("capture_id", flat=True))
    rows, counts = [], dict.fromkeys(STATES, 0)
    for c in captures:
        summary = summaries.get(c.pk)
        state = capture_state(c.n_reviews > 0, c.pk in gold, summary)
        counts[state] += 1
        rows.append({
            "id": c.pk, "name": c.name, "state": state, "reviews": c.n_reviews,
            "submitted": c.n_submitted,
            "boundary_f1": summary.boundary_f1 if summary else None,
            "label_agreement": summary.label_agreement if summary else None,
        })
    from segmentation.services.assignments import assignment_summary

    team = assignment_summary([row["id"] for row in rows])
    for row in rows:
        row["assigned"] = team[row["id"]]["assigned"]
        row["review_states"] = team[row["id"]]["reviews"]
    return {"project": project.pk, "states": counts, "captures": rows,
            "annotators": annotator_throughput(project), "labels": label_agreement(summaries),
            "library": library_counts(project)}


def annotator_throughput(project):
    """Per annotator: reviews, edits by kind (from the audit log), time per review."""
    people = {}
    reviews = Review.objects.filter(capture__project=project).select_related("annotator")
    for r in reviews:
        person = people.setdefault(r.annotator_id, {
            "id": r.annotator_id, "username": r.annotator.username, "submitted": 0,
            "in_progress": 0, "edits": dict.fromkeys(EDIT_ACTIONS, 0), "edits_total": 0,
            "_minutes": []})
        person["submitted" if r.status == "submitted" else "in_progress"] += 1
        if r.submitted_at:
            person["_minutes"].append((r.submitted_at - r.created_at).total_seconds() / 60)
    events = (
        ReviewEvent.objects.filter(review__capture__project=project, action__in=EDIT_ACTIONS)
        .values("review__annotator_id", "action").annotate(n=Count("id"))
    )
    for e in events:
        person = people.get(e["review__annotator_id"])
        if person:
            person["edits"][e["action"]] = e["n"]
            person["edits_total"] += e["n"]
    for person in people.values():
        minutes = person.pop("_minutes")
        person["median_minutes_per_review"] = round(median(minutes), 2) if minutes else None
        person["edits_per_review"] = (
            round(person["edits_total"] / person["submitted"], 2) if person["submitted"] else None
        )
    return sorted(people.values(), key=lambda p: p["username"])


def label_agreement(summaries):
    """Per label over the project's captures: frame-weighted mean overlap."""
    totals = {}
    for summary in summaries.values():
        for name, v in summary.per_label.items():
            if v["overlap"] is None:
                continue
            entry = totals.setdefault(name, [0.0, 0, 0])
            entry[0] += v["overlap"] * v["frames"]
            entry[1] += v["frames"]
            entry[2] += 1
    return [
        {"label": name, "overlap": round(w / frames, 4) if frames else None,
         "frames": frames, "captures": n}
        for name, (w, frames, n) in sorted(totals.items())
    ]


def library_counts(project):
    """Segments in the library by kind (shown on the dashboard)."""
    segments = LibrarySegment.objects.filter(project=project)
    return segments.aggregate(
        total=Count("id", filter=Q(superseded=False)), gold=Count("id", filter=Q(is_gold=True))
    )
