"""A review's history, read from its audit log: the review as it was after any listed
event, undo and redo that survive a reload, and restoring an earlier point.

Every edit's event keeps the state before and after it (a cut's frame and fate, a
segment's label by the cut that starts it), so the review after event E is the review
now with every later event taken back, newest first. A restore writes that state in one
transaction and is itself one event, whose before/after list what it changed, so it can
be taken back like any edit.

Undo and redo are restores with an intent. Reading the log in order, an edit (or a plain
restore) is a step onto the undo stack and clears the redo stack; an undo moves the top
step to the redo stack, a redo moves it back. Undoing step S restores the point just
before S; redoing it restores the point right after S.
"""

from django.db import transaction

from segmentation.errors import Invalid
from segmentation.models import Cut, SegmentLabel
from segmentation.services.reviews import _log, _write

#: Events that change cuts or labels and so are steps of the undo history.
STEP_ACTIONS = frozenset({"insert", "accept", "delete", "reset", "move", "label", "restore",
                          "import"})
CUT_ACTIONS = frozenset({"insert", "accept", "delete", "reset", "move"})


def current_state(review):
    """``(cuts, labels)``: ``{cut id: (frame, fate)}`` and ``{start cut id or None: label}``."""
    cuts = {pk: (frame, fate) for pk, frame, fate in review.cuts.values_list("pk", "frame", "fate")}
    labels = dict(review.segment_labels.values_list("cut_id", "label__name"))
    return cuts, labels


def state_after(review, event):
    """The review's cuts and labels as they were right after ``event``."""
    cuts, labels = current_state(review)
    candidates = set(review.cuts.filter(origin="candidate").values_list("pk", flat=True))
    for later in review.events.filter(pk__gt=event.pk).order_by("-pk"):
        _take_back(later, cuts, labels, candidates)
    return cuts, labels


def _take_back(event, cuts, labels, candidates):
    """Undo one event on the state (in place)."""
    before, after = event.before or {}, event.after or {}
    if event.action == "label":
        labels[event.cut_id] = before.get("label")
    elif event.action in ("restore", "import"):
        # An import (services.annotations) lists what it changed as a restore does.
        cuts.update({pk: (frame, fate) for pk, frame, fate in before.get("cuts", [])})
        labels.update({cut_id: label for cut_id, label in before.get("labels", [])})
    elif event.action == "candidates":
        # A review started before detection finished took every candidate in at once.
        cuts.update({pk: (cuts[pk][0], "deleted") for pk in candidates})
    elif event.action == "insert" and event.cut_id in cuts:
        cuts[event.cut_id] = (after["frame"], "deleted")  # it did not exist before
    elif event.action in CUT_ACTIONS and event.cut_id in cuts:
        cuts[event.cut_id] = (before["frame"], before["fate"])


def undo_steps(events):
    """``(past, future)``: the event ids of the steps undo and redo would take, top last.

    ``events`` are ``(id, action, after)`` in log order.
    """
    past, future = [], []
    for pk, action, after in events:
        intent = (after or {}).get("intent") if action == "restore" else None
        if intent == "undo" and past:
            future.append(past.pop())
        elif intent == "redo" and future:
            past.append(future.pop())
        elif intent is None and action in STEP_ACTIONS:
            past.append(pk)
            future = []
    return past, future


def do_restore_review(review, user, event_id, version, intent=None):
    """Restore ``review`` as it was right after its event ``event_id``; one "restore" event."""
    with transaction.atomic():
        _write(review, version)
        event = review.events.filter(pk=event_id).first()
        if event is None:
            raise Invalid(f"event: review {review.pk} has no event {event_id}")
        _restore(review, user, event, intent)
    return review


def do_undo(review, user, version):
    """Take back the caller's last step (an edit or a restore), even one made before a reload."""
    return _step(review, user, version, "undo")


def do_redo(review, user, version):
    """Make the last undone step again."""
    return _step(review, user, version, "redo")


def _step(review, user, version, intent):
    with transaction.atomic():
        # The version is claimed first: the log read below is the one the write follows.
        _write(review, version)
        log = list(review.events.order_by("pk").values_list("pk", "action", "after"))
        past, future = undo_steps(log)
        stack = past if intent == "undo" else future
        if not stack:
            raise Invalid(f"{intent}: review {review.pk} has nothing to {intent}")
        ids = [pk for pk, _, _ in log]
        # Undo goes to the point just before the step; redo to the point right after it.
        target = ids[ids.index(stack[-1]) - 1] if intent == "undo" else stack[-1]
        _restore(review, user, review.events.get(pk=target), intent)
    return review


def _restore(review, user, event, intent):
    cuts, labels = state_after(review, event)
    _check_consistent(review, event, cuts)
    now_cuts, now_labels = current_state(review)
    changed_cuts = sorted((pk, *state) for pk, state in cuts.items() if now_cuts.get(pk) != state)
    changed_labels = [(cut_id, label) for cut_id, label in labels.items()
                      if now_labels.get(cut_id) != label and (cut_id is None or cut_id in now_cuts)]
    for pk, frame, fate in changed_cuts:
        Cut.objects.filter(pk=pk, review=review).update(frame=frame, fate=fate)
    project_labels = dict(review.capture.project.labels.values_list("name", "pk"))
    for cut_id, label in changed_labels:
        SegmentLabel.objects.update_or_create(
            review=review, cut_id=cut_id, defaults={"label_id": project_labels.get(label)})
    before = {"cuts": [[pk, *now_cuts[pk]] for pk, _, _ in changed_cuts],
              "labels": [[cut_id, now_labels.get(cut_id)] for cut_id, _ in changed_labels]}
    after = {"event": event.pk, "at": event.created_at.isoformat(), "intent": intent,
             "cuts": [list(c) for c in changed_cuts], "labels": [list(lab) for lab in changed_labels]}
    _log(review, user, "restore", before=before, after=after)


def _check_consistent(review, event, cuts):
    """Two kept cuts on one frame would mean the log does not describe the review."""
    kept = [frame for frame, fate in cuts.values() if fate != "deleted"]
    if len(kept) != len(set(kept)):
        raise Invalid(f"event: review {review.pk} cannot be restored to event {event.pk}: "
                      "its log does not account for every cut")
