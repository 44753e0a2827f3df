"""Assignments and queues: handing captures to annotators, and each one's queue.

"Each capture to N annotators" spreads the work evenly: every capture goes to the N
annotators of the chosen pool who hold the fewest open assignments in the project at
that moment (counting the ones just made), ties broken by the pool's order. A capture
already assigned to someone in the pool counts towards its N.
"""

from django.db import transaction
from django.utils import timezone

from segmentation.errors import Invalid, NotAllowed
from segmentation.models import Assignment, Capture, Membership, Review


def members_by_username(project, usernames):
    """The project's members with these usernames, in the given order; ValueError names
    anyone who is not a member."""
    if not isinstance(usernames, list) or not usernames:
        raise Invalid("annotators: give a non-empty list of usernames")
    found = {
        m.user.username: m.user
        for m in Membership.objects.filter(project=project, user__username__in=usernames).select_related("user")
    }
    missing = [u for u in usernames if u not in found]
    if missing:
        raise Invalid(f"annotators: not members of this project: {', '.join(map(str, missing))}")
    return [found[u] for u in dict.fromkeys(usernames)]


def project_captures(project, capture_ids):
    if not isinstance(capture_ids, list) or not capture_ids:
        raise Invalid("captures: give a non-empty list of capture ids")
    captures = {c.pk: c for c in Capture.objects.filter(project=project, pk__in=capture_ids)}
    missing = [pk for pk in capture_ids if pk not in captures]
    if missing:
        raise Invalid(f"captures: not captures of this project: {', '.join(map(str, missing))}")
    return [captures[pk] for pk in dict.fromkeys(capture_ids)]


def open_load(project, users):
    """Per user id: assignments in the project whose review is not submitted yet."""
    assigned = Assignment.objects.filter(capture__project=project, annotator__in=users)
    done = set(Review.objects.filter(capture__project=project, annotator__in=users, status="submitted")
               .values_list("annotator_id", "capture_id"))
    load = {u.pk: 0 for u in users}
    for pair in assigned.values_list("annotator_id", "capture_id"):
        load[pair[0]] += pair not in done
    return load


def do_assign(project, actor, capture_ids, usernames, per_capture=None):
    """Assign captures to annotators; returns the new ``Assignment`` rows.

    Without ``per_capture`` every capture goes to every listed annotator; with it, each
    capture goes to ``per_capture`` of them, spread evenly (see the module docstring).
    """
    captures = project_captures(project, capture_ids)
    pool = members_by_username(project, usernames)
    if per_capture is None:
        per_capture = len(pool)
    if isinstance(per_capture, bool) or not isinstance(per_capture, int) or not 1 <= per_capture <= len(pool):
        raise Invalid(f"per_capture: must be between 1 and {len(pool)} (the annotators given), "
                      f"got {per_capture!r}")
    made = []
    with transaction.atomic():
        # One assignment run at a time per project, so two spreads do not both pick the
        # same least-loaded annotator from the same stale counts.
        type(project).objects.select_for_update().get(pk=project.pk)
        load = open_load(project, pool)
        for capture in captures:
            have = set(capture.assignments.values_list("annotator_id", flat=True))
            need = per_capture - len(have & set(load))
            ranked = sorted((u for u in pool if u.pk not in have), key=lambda u: load[u.pk])
            for user in ranked[:max(need, 0)]:
                made.append(Assignment.objects.create(capture=capture, annotator=user, assigned_by=actor))
                load[user.pk] += 1
    return made


def do_unassign(assignment):
    """Withdraw an assignment; the annotator's review, if any, stays as it is."""
    assignment.delete()


def do_reassign(assignment, actor, username):
    """Give an assignment to another member (refused if they already have the capture)."""
    (user,) = members_by_username(assignment.capture.project, [username])
    with transaction.atomic():
        if Assignment.objects.filter(capture=assignment.capture, annotator=user).exists():
            raise Invalid(f"annotator: {username!r} is already assigned to {assignment.capture.name!r}")
        assignment.annotator, assignment.assigned_by = user, actor
        assignment.created_at = timezone.now()
        assignment.save(update_fields=["annotator", "assigned_by", "created_at"])
    return assignment


def check_may_start(capture, user):
    """Refuse an annotator a new review of a capture not assigned to them when the project
    does not let annotators pick unassigned captures (reviewers and admins always may)."""
    project = capture.project
    if project.annotators_pick_unassigned or project.can_see_all_reviews(user):
        return
    if not capture.assignments.filter(annotator=user).exists():
        raise NotAllowed(f"{capture.name!r} is not assigned to you, and this project lets "
                         "annotators review only the captures assigned to them")
