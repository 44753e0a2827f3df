"""Records of the clip library and of agreement between annotators.

- ``LibrarySegment``: one labelled segment of a submitted review, or of a capture's gold
  version, materialised as a row (frames, duration, label, annotator, agreement and the
  motion descriptor) when the review is submitted or the gold version saved, so that
  library queries are plain indexed queries.
- ``Adjudication``: the gold version of a capture, made by a reviewer.
- ``CaptureAgreement``: the agreement summary of a capture's submitted reviews at the
  default tolerance, kept for the project dashboard.
- ``LabelSuggestion``, ``SuggestionRequest``: label suggestions computed from the library
  (see below and ``segmentation.similar.suggestions``).
"""

import numpy as np
from django.conf import settings
from django.db import models
from django.db.models import OuterRef, Q, Subquery
from django.utils import timezone

from segmentation.db.statements import Statement
from segmentation.models.captures import Capture
from segmentation.models.projects import Label, Membership, Project
from segmentation.models.reviews import Review

# A capture whose annotators agree this well needs no adjudication.
AGREED_BOUNDARY_F1 = 0.8
AGREED_LABELS = 0.8
# Roles that see every segment of their project; an annotator sees own and gold ones.
STAFF = ("reviewer", "admin")


def own(user):
    """Q of an annotator's own segments and the gold ones (``is_gold__in``: see
    ``segmentation.queries.library.segment_filters``); ``user`` or their id."""
    return Q(annotator=user) | Q(is_gold__in=[True])


def projects_by_role(user):
    """``(staff, annotating)``: ids of the projects ``user`` reviews or administers, and
    of those they annotate (by id, in a statement compiled once: the list reads it per
    request)."""
    staff, annotating = [], []
    for project_id, role in _ROLES.rows(Membership.objects.db, None, user=user.pk):
        (staff if role in STAFF else annotating).append(project_id)
    return staff, annotating


_ROLES = Statement(lambda key, user: Membership.objects.filter(user_id=user).order_by("project_id")
                   .values_list("project_id", "role"))


def one_project_of(ids):
    return Q(project_id=ids[0]) if len(ids) == 1 else Q(project_id__in=ids)


class LibrarySegmentQuerySet(models.QuerySet):
    def visible_to(self, user):
        """Segments of the user's projects: everything for reviewers and admins, own and
        gold segments for annotators, nothing for anybody else."""
        if not user.is_authenticated:
            return self.none()
        return self.visible_among(*projects_by_role(user), user)

    def visible_among(self, staff, annotating, user):
        """``visible_to`` a ``user`` (or their id) who reviews or administers the projects
        ``staff`` and annotates ``annotating`` (``projects_by_role``)."""
        return self.filter(Q(project_id__in=staff) | Q(project_id__in=annotating) & own(user))

    def visible_in(self, project_id, user_id, role):
        """``visible_to`` within one project, for the ``role`` user ``user_id`` has there,
        read already (``with_role_of``): None sees nothing."""
        if role is None:
            return self.none()
        mine = self.filter(project_id=project_id)
        return mine if role in STAFF else mine.filter(own(user_id))

    def with_role_of(self, user_id):
        """Each segment annotated with ``role``: user ``user_id``'s role in its project, or
        None. With ``visible_in`` it reads a segment and decides what its project shows the
        user in one query (``visible_to`` reads the user's memberships first)."""
        roles = Membership.objects.filter(project_id=OuterRef("project_id"), user_id=user_id)
        return self.annotate(role=Subquery(roles.values("role")[:1]))

    def runs_among(self, staff, annotating, user):
        """``visible_among(staff, annotating, user)`` as querysets that share no row: the
        projects ``staff``; in the projects ``annotating``, the user's own segments, and
        the gold ones. Unlike ``visible_to``'s OR, each can be read in id order from an
        index. No queryset when the user sees nothing.

        One project is written as an equality: SQLite reads it as an index prefix, where
        ``project_id IN (…) AND project_id = 7`` can make it pick a worse index.
        """
        runs = [self.filter(one_project_of(staff))] if staff else []
        if annotating:
            theirs = self.filter(one_project_of(annotating))
            # Gold rows have no annotator; ``exclude`` keeps the runs apart whatever the rows say.
            runs += [theirs.filter(annotator=user),
                     theirs.filter(is_gold__in=[True]).exclude(annotator=user)]
        return runs

    def preferred(self):
        """The library's default view: gold where a capture has it, else every annotator's."""
        return self.filter(superseded=False)


class LibrarySegment(models.Model):
    project = models.ForeignKey(Project, models.CASCADE, related_name="+")
    capture = models.ForeignKey(Capture, models.CASCADE, related_name="library_segments")
    review = models.ForeignKey(Review, models.CASCADE, null=True, blank=True, related_name="+")
    annotator = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.CASCADE, null=True, blank=True, related_name="+"
    )
    is_gold = models.BooleanField(default=False)
    # An annotator's segment of a capture that has a gold version.
    superseded = models.BooleanField(default=False)
    # By identity: a renamed label shows its new name on every segment at once, and a
    # label that segments carry cannot be deleted from under them.
    label = models.ForeignKey(Label, models.RESTRICT, related_name="+")
    start = models.PositiveIntegerField()
    stop = models.PositiveIntegerField()
    duration = models.FloatField()
    # Share of the other annotators' frames that carry the same label (NaN -> null).
    agreement = models.FloatField(null=True, blank=True)
    # float32 (rows, cols) motion descriptor, see motionlib.similarity; null when the
    # skeleton cannot be mapped to body parts.
    descriptor = models.BinaryField(null=True, blank=True)
    descriptor_shape = models.JSONField(null=True, blank=True)
    # The descriptor's first rows (motionlib.similarity.PROFILE_ROWS), kept apart so the
    # first stage of a similar-clip search reads a tenth of the bytes.
    profile = models.BinaryField(null=True, blank=True)
    created_at = models.DateTimeField(default=timezone.now)

    objects = LibrarySegmentQuerySet.as_manager()

    class Meta:
        ordering = ["-id"]
        indexes = [
            models.Index(fields=["project", "superseded", "-id"], name="libseg_project_recent"),
            models.Index(fields=["project", "label", "duration"], name="libseg_label_duration"),
            models.Index(fields=["project", "annotator", "-id"], name="libseg_annotator"),
            models.Index(fields=["project", "is_gold", "-id"], name="libseg_gold"),
            models.Index(fields=["project", "agreement"], name="libseg_agreement"),
            models.Index(fields=["project", "duration"], name="libseg_duration"),
            # The list's default view in its default order, with every filtered column, so
            # that a page's ids and a capped count come from the index alone.
            models.Index(fields=["project", "superseded", "-id"], name="libseg_list_recent",
                         include=["label", "duration", "agreement", "annotator", "is_gold",
                                  "capture"]),
            # The same across projects (every project a reviewer sees, an annotator's own
            # and gold segments).
            models.Index(fields=["superseded", "-id"], name="libseg_list_all",
                         include=["project", "label", "duration", "agreement", "annotator",
                                  "is_gold", "capture"]),
            # The same for a label (its segments newest first, or every label in order) and
            # for an annotator.
            models.Index(fields=["project", "superseded", "label", "id"], name="libseg_list_label",
                         include=["duration", "agreement", "annotator", "is_gold", "capture"]),
            models.Index(fields=["project", "superseded", "annotator", "-id"],
                         name="libseg_list_annotator",
                         include=["label", "duration", "agreement", "is_gold", "capture"]),
            models.Index(fields=["project", "superseded", "-agreement", "-id"],
                         name="libseg_list_agreement",
                         include=["label", "duration", "annotator", "is_gold", "capture"]),
            # The similar-clip index reads a project's described segments by id (all of
            # them, or those newer than the index file).
            models.Index(fields=["project", "id"], name="libseg_described",
                         condition=Q(profile__isnull=False)),
        ]

    def __str__(self):
        return f"label {self.label_id} {self.start}-{self.stop} of {self.capture_id}"

    def descriptor_array(self):
        if self.descriptor is None:
            return None
        return np.frombuffer(bytes(self.descriptor), dtype="<f4").reshape(self.descriptor_shape)


class Adjudication(models.Model):
    """The gold version of a capture: cut frames and one label per segment.

    ``labels`` has ``len(cuts) + 1`` entries, one per segment in frame order: the id of a
    label of the capture's project, or null. Ids, not names, so that a rename or a retire
    leaves the gold version as it was. ``version`` guards against two reviewers
    overwriting each other.
    """

    capture = models.OneToOneField(Capture, models.CASCADE, related_name="adjudication")
    adjudicator = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+"
    )
    source_review = models.ForeignKey(
        Review, models.SET_NULL, null=True, blank=True, related_name="+"
    )
    cuts = models.JSONField(default=list)
    labels = models.JSONField(default=list)
    version = models.PositiveIntegerField(default=1)
    created_at = models.DateTimeField(default=timezone.now)
    updated_at = models.DateTimeField(default=timezone.now)

    def __str__(self):
        return f"gold version of {self.capture}"

    def label_segments(self):
        """``[(start, stop, label id or None)]`` in frame order."""
        bounds = [0, *self.cuts, self.capture.n_frames]
        return list(zip(bounds[:-1], bounds[1:], self.labels, strict=True))

    def label_names(self):
        """The labels' current names, one per segment (None where unlabelled)."""
        names = dict(Label.objects.filter(pk__in=[x for x in self.labels if x is not None])
                     .values_list("id", "name"))
        return [names[x] if x is not None else None for x in self.labels]

    def segments(self):
        """``[(start, stop, label name or None)]`` in frame order, with current names."""
        bounds = [0, *self.cuts, self.capture.n_frames]
        return list(zip(bounds[:-1], bounds[1:], self.label_names(), strict=True))


class CaptureAgreement(models.Model):
    """Agreement of a capture's submitted reviews at the default tolerance."""

    capture = models.OneToOneField(Capture, models.CASCADE, related_name="agreement")
    n_reviews = models.PositiveIntegerField()
    boundary_f1 = models.FloatField(null=True, blank=True)
    # Cohen's kappa for two reviews, Krippendorff's alpha for more.
    label_agreement = models.FloatField(null=True, blank=True)
    # {label id (a string, as JSON keys are): {"overlap": IoU, "frames": n}}
    per_label = models.JSONField(default=dict)
    computed_at = models.DateTimeField(default=timezone.now)

    def __str__(self):
        return f"agreement on {self.capture}"

    @property
    def agreed(self):
        return (
            self.n_reviews >= 2
            and (self.boundary_f1 or 0) >= AGREED_BOUNDARY_F1
            and (self.label_agreement or 0) >= AGREED_LABELS
        )


# Stored label suggestions, shared by every web and worker process.
#
# - ``LabelSuggestion``: the suggested label of one span of a capture, computed against
#   one state of one pool of library segments (``suggestions.pool_key``: everything, gold
#   only, or gold plus one annotator's own). Annotators whose pools are the same share the
#   rows; a row of an older state of a pool is stale and never read.
# - ``SuggestionRequest``: one per (capture, annotator): when suggestions were last asked
#   of a worker and when that worker finished, so that twenty page loads send one job.
#
# See ``segmentation.similar.suggestions``.


class LabelSuggestion(models.Model):
    capture = models.ForeignKey(Capture, models.CASCADE, related_name="+")
    # ``suggestions.pool_key``: which segments the label came from, and their state.
    pool = models.CharField(max_length=100)
    start = models.PositiveIntegerField()
    stop = models.PositiveIntegerField()
    # Null when nothing in the pool can name the span (no descriptor, empty pool).
    label = models.ForeignKey(Label, models.CASCADE, null=True, blank=True, related_name="+")
    # A frame model's proposal (pool ``p:<pool key>``, ``similar.proposals``): the mean
    # probability of ``label`` over the span; null for a library suggestion.
    probability = models.FloatField(null=True, blank=True)

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["capture", "pool", "start", "stop"],
                                    name="one_suggestion_per_span")
        ]

    def __str__(self):
        return f"label {self.label_id or '-'} for {self.start}-{self.stop} of {self.capture_id}"


class SuggestionRequest(models.Model):
    capture = models.ForeignKey(Capture, models.CASCADE, related_name="+")
    annotator = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="+")
    asked_at = models.DateTimeField(null=True, blank=True)
    done_at = models.DateTimeField(null=True, blank=True)
    # The last job's failure (it is not asked again for a while: see suggestions.ask).
    failed_at = models.DateTimeField(null=True, blank=True)
    error = models.TextField(blank=True, default="")
    created_at = models.DateTimeField(default=timezone.now)

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["capture", "annotator"], name="one_suggestion_request")
        ]

    def __str__(self):
        return f"suggestions for {self.annotator_id} on {self.capture_id}"
