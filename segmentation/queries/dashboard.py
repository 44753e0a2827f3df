"""The project dashboard: where each capture stands, annotators' throughput, agreement per
label and the library's size (agreement itself is ``segmentation.services.agreement``)."""

from statistics import median

from django.db.models import Count, Q

from segmentation.models import (
    Adjudication,
    Assignment,
    Capture,
    CaptureAgreement,
    LibrarySegment,
    Review,
    ReviewEvent,
)

EDIT_ACTIONS = ("accept", "delete", "reset", "move", "insert", "label")


STATES = ("unreviewed", "in_review", "agreed", "adjudicated")


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
    team = assignment_summary([row["id"] for row in rows])
    for row in rows:
        row["assigned"] = team[row["id"]]["assigned"]
        row["review_states"] = team[row["id"]]["reviews"]
    return {"project": project.pk, "states": counts, "captures": rows,
            "annotators": annotator_throughput(project), "labels": label_agreement(summaries, dict(project.labels.values_list("id", "name"))),
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


def label_agreement(summaries, names):
    """Per label over the project's captures: frame-weighted mean overlap, under the
    labels' current ``names`` (by id)."""
    totals = {}
    for summary in summaries.values():
        for label_id, v in summary.per_label.items():
            if v["overlap"] is None or int(label_id) not in names:
                continue
            entry = totals.setdefault(names[int(label_id)], [0.0, 0, 0])
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


def assignment_summary(capture_ids):
    """Per capture id: who is assigned and each review's state (the dashboard)."""
    out = {pk: {"assigned": [], "reviews": []} for pk in capture_ids}
    for a in Assignment.objects.filter(capture_id__in=capture_ids).select_related("annotator"):
        out[a.capture_id]["assigned"].append(a.annotator.username)
    reviews = Review.objects.filter(capture_id__in=capture_ids).select_related("annotator")
    for r in reviews.order_by("id"):
        out[r.capture_id]["reviews"].append({"id": r.pk, "annotator": r.annotator.username,
                                             "status": r.status})
    return out
