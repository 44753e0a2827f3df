"""What a caller may open: one record among those their memberships let them see.

Every view that takes a capture, project or segment id starts here. A record the caller
may not see is answered as one that does not exist (``Missing``, a 404): a 403 would say
that it exists.
"""

from django.shortcuts import get_object_or_404

from segmentation.errors import Missing, NotAllowed
from segmentation.models import Capture, LibrarySegment, Project


def capture_for(user, pk):
    """A capture of one of the user's projects, or 404."""
    capture = Capture.objects.visible_to(user).filter(pk=pk).first()
    if capture is None:
        raise Missing("No such capture.")
    return capture


def project_for(user, pk):
    """A project the user is a member of, or 404 (never 403, which would leak it)."""
    return get_object_or_404(Project.objects.for_user(user), pk=pk)


def staff_capture(user, pk):
    """A capture whose project the user reviews or administers; 404 for outsiders, 403
    (saying why) for an annotator, who sees the capture anyway."""
    capture = capture_for(user, pk)
    if not capture.project.can_see_all_reviews(user):
        raise NotAllowed("Only the project's reviewers and admins see agreement and "
                         "adjudicate; you annotate in this project.")
    return capture


def segment_for(user, pk):
    """A library segment the user sees (``LibrarySegment.objects.visible_to``), with its
    capture, annotator and label, or 404."""
    segment = (LibrarySegment.objects.visible_to(user).select_related("capture", "annotator", "label")
               .filter(pk=pk).first())
    if segment is None:
        raise Missing("No such segment.")
    return segment
