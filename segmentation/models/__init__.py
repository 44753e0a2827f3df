"""Cutroom's records, one module per noun (same app label, same migrations).

- ``jobs``: the claimable background-work row shared by captures, runs and trainings;
- ``projects``: projects, members, labels, invitations, the project's cut model;
- ``captures``: captures, detection runs, assignments;
- ``reviews``: reviews, cuts, segment labels, the review audit log;
- ``library``: library segments, gold versions, agreement, label suggestions;
- ``workers``: the Celery workers' heartbeats;
- ``comments``: threads of comments pinned to a frame, cut or segment of a review;
- ``attributes``: a project's segment attribute schema and the values segments carry;
- ``videos``: reference videos played in sync with a capture;

Rules about one record live on the models; lookups live on the managers
(``Capture.objects.visible_to(user)``). Workflows that touch several records are the
``do_*`` functions in ``segmentation.services``.
"""

from segmentation.models.attributes import (
    GoldAttributeValue,
    LibraryAttributeValue,
    SegmentAttribute,
    SegmentAttributeValue,
)
from segmentation.models.captures import (
    Assignment,
    Capture,
    CaptureQuerySet,
    DetectionRun,
    derived_path,
    original_path,
)
from segmentation.models.comments import Comment
from segmentation.models.jobs import JOB_STATUSES, ClaimQuerySet, Job, JSONArrayLength
from segmentation.models.library import (
    AGREED_BOUNDARY_F1,
    AGREED_LABELS,
    Adjudication,
    CaptureAgreement,
    LabelSuggestion,
    LibrarySegment,
    SuggestionRequest,
)
from segmentation.models.projects import (
    ROLES,
    Invitation,
    Label,
    Membership,
    Project,
    ProjectCutModel,
)
from segmentation.models.reviews import Cut, Review, ReviewEvent, SegmentLabel
from segmentation.models.videos import ReferenceVideo
from segmentation.models.workers import WorkerHeartbeat

__all__ = [
    "AGREED_BOUNDARY_F1",
    "AGREED_LABELS",
    "JOB_STATUSES",
    "ROLES",
    "Adjudication",
    "Assignment",
    "Capture",
    "CaptureAgreement",
    "CaptureQuerySet",
    "Comment",
    "ClaimQuerySet",
    "Cut",
    "DetectionRun",
    "GoldAttributeValue",
    "Invitation",
    "JSONArrayLength",
    "Job",
    "Label",
    "LabelSuggestion",
    "LibraryAttributeValue",
    "LibrarySegment",
    "Membership",
    "Project",
    "ProjectCutModel",
    "ReferenceVideo",
    "Review",
    "ReviewEvent",
    "SegmentAttribute",
    "SegmentAttributeValue",
    "SegmentLabel",
    "SuggestionRequest",
    "derived_path",
    "original_path",
    "WorkerHeartbeat",
]
