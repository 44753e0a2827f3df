"""Projects and who works in them: members and their roles, the label taxonomy,
invitations to join, and the project's learnt cut model."""

from django.conf import settings
from django.db import models
from django.db.models import Q
from django.utils import timezone

from segmentation.models.jobs import ClaimQuerySet, Job, claim_cutoff

ROLES = (("annotator", "Annotator"), ("reviewer", "Reviewer"), ("admin", "Admin"))


class ProjectQuerySet(models.QuerySet):
    def for_user(self, user):
        """Projects the user is a member of (any role)."""
        if not user.is_authenticated:
            return self.none()
        return self.filter(memberships__user=user)


class Project(models.Model):
    """A studio's library: members, label taxonomy, default segmentation method.

    An empty ``default_method`` means "the registry's recommended method", resolved at
    detection time (see ``services.default_method``).
    """

    name = models.CharField(max_length=200)
    default_method = models.CharField(max_length=100, blank=True)
    default_params = models.JSONField(default=dict, blank=True)
    # Whether annotators may start reviewing captures nobody assigned to them.
    annotators_pick_unassigned = models.BooleanField(default=True)
    created_at = models.DateTimeField(default=timezone.now)

    objects = ProjectQuerySet.as_manager()

    def __str__(self):
        return self.name

    def role_of(self, user):
        """The user's role in this project, or None for a non-member."""
        if not user.is_authenticated:
            return None
        member = self.memberships.filter(user=user).first()
        return member.role if member else None

    def can_manage(self, user):
        return self.role_of(user) == "admin"

    def can_see_all_reviews(self, user):
        return self.role_of(user) in ("reviewer", "admin")


class Membership(models.Model):
    project = models.ForeignKey(Project, models.CASCADE, related_name="memberships")
    user = models.ForeignKey(settings.AUTH_USER_MODEL, models.CASCADE, related_name="memberships")
    role = models.CharField(max_length=20, choices=ROLES, default="annotator")

    class Meta:
        constraints = [
            models.UniqueConstraint(fields=["project", "user"], name="one_membership_per_user")
        ]

    def __str__(self):
        return f"{self.user} in {self.project} ({self.role})"


class Label(models.Model):
    """One entry of a project's label taxonomy (walk, punch…)."""

    project = models.ForeignKey(Project, models.CASCADE, related_name="labels")
    name = models.CharField(max_length=100)
    color = models.CharField(max_length=7, default="#888888")
    # NULL, not "", means "no hotkey" so that only real hotkeys must be unique.
    hotkey = models.CharField(max_length=1, null=True, blank=True)  # noqa: DJ001
    # The taxonomy's order in the app; a retired label stays on existing segments but
    # is no longer offered for new ones.
    position = models.PositiveIntegerField(default=0)
    retired = models.BooleanField(default=False)

    class Meta:
        ordering = ["position", "id"]
        constraints = [
            models.UniqueConstraint(fields=["project", "name"], name="unique_label_name"),
            models.UniqueConstraint(
                fields=["project", "hotkey"],
                condition=Q(hotkey__isnull=False),
                name="unique_label_hotkey",
            ),
        ]

    def __str__(self):
        return self.name


# Invitations to join a project.
#
# Nobody is placed in a project without saying yes: a project admin invites a *username*,
# and the account of that name sees the invitation and accepts or declines it. An
# invitation names a username rather than a user so that inviting a name no account has
# looks, to the inviter, exactly like inviting a person: same answer, same pending list.
# That keeps usernames from being enumerated through projects anyone can create.
#
# Rows are never deleted (short of deleting the project): they are the record of who
# invited whom to what role, when, and who accepted, declined or cancelled it, when.


class InvitationQuerySet(models.QuerySet):
    def pending(self):
        """Not yet answered and not expired."""
        return self.filter(status="pending", expires_at__gt=timezone.now())

    def for_user(self, user):
        """The pending invitations addressed to the user's username."""
        if not user.is_authenticated:
            return self.none()
        return self.pending().filter(username=user.get_username())


class Invitation(models.Model):
    STATUSES = (
        ("pending", "Pending"),
        ("accepted", "Accepted"),
        ("declined", "Declined"),
        ("cancelled", "Cancelled"),
    )

    project = models.ForeignKey(Project, models.CASCADE, related_name="invitations")
    username = models.CharField(max_length=150)
    role = models.CharField(max_length=20, choices=ROLES)
    invited_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, related_name="+"
    )
    created_at = models.DateTimeField(default=timezone.now)
    expires_at = models.DateTimeField()
    status = models.CharField(max_length=20, choices=STATUSES, default="pending")
    # Who accepted or declined it (the invitee) or cancelled it (a project admin), and when.
    answered_by = models.ForeignKey(
        settings.AUTH_USER_MODEL, models.SET_NULL, null=True, blank=True, related_name="+"
    )
    answered_at = models.DateTimeField(null=True, blank=True)

    objects = InvitationQuerySet.as_manager()

    class Meta:
        ordering = ["id"]
        constraints = [
            models.UniqueConstraint(
                fields=["project", "username"], condition=Q(status="pending"),
                name="one_pending_invitation_per_username",
            )
        ]
        indexes = [models.Index(fields=["username", "status"], name="invitation_username_status")]

    def __str__(self):
        return f"{self.username} to {self.project} as {self.role} ({self.status})"


class CutModelQuerySet(ClaimQuerySet):
    def claim(self, pk, token):
        """Claim a training unless another training of the same project holds a live
        claim: one training at a time per project. Zero rows updated means it is not
        this job's turn (or another worker has it)."""
        busy = self.model.objects.filter(
            project=models.OuterRef("project"), status="processing", claimed_at__gte=claim_cutoff()
        ).exclude(pk=models.OuterRef("pk"))
        return super(CutModelQuerySet, self.filter(~models.Exists(busy))).claim(pk, token)

    def newest(self, project_id):
        """The project's newest model in use, or None (zero-shot). A refused model has no
        version and is never in use."""
        return (
            self.filter(project_id=project_id, status="ready", version__isnull=False)
            .order_by("-version")
            .first()
        )


class ProjectCutModel(Job):
    """One training of a project's cut model from its reviewed takes.

    A row is one request: queued when a review is submitted or a gold version saved
    (later requests fold into the queued one), then trained by a worker. A trained row
    gets the project's next ``version`` if the gate accepts it; a model the gate refused
    is kept (``status`` ready) with no version and the reason in ``refused``; a failed
    training keeps its ``error`` and no version. Detection goes on with the newest
    version. ``model`` is ``motionlib.adapt.CutModel.to_json()``.

    ``trained_on`` lists the captures the model learnt from, so that a later training
    can score it on the takes it did not see; ``held_out_*`` is the model's own figure,
    each reviewed take scored by a model fitted without it (see
    ``services.model_gate``).
    """

    project = models.ForeignKey(Project, models.CASCADE, related_name="cut_models")
    version = models.PositiveIntegerField(null=True, blank=True)
    model = models.TextField(blank=True)
    # motionlib.labelling.FrameModel.to_json() of the same examples, labels by id ("":
    # no labelled segment to learn from).
    labels_model = models.TextField(blank=True, default="")
    n_takes = models.PositiveIntegerField(default=0)
    n_cuts = models.PositiveIntegerField(default=0)
    seconds = models.FloatField(null=True, blank=True)
    created_at = models.DateTimeField(default=timezone.now)
    finished_at = models.DateTimeField(null=True, blank=True)
    trained_on = models.JSONField(default=list, blank=True)
    held_out_takes = models.PositiveIntegerField(null=True, blank=True)
    held_out_edits_per_cut = models.FloatField(null=True, blank=True)
    held_out_f1 = models.FloatField(null=True, blank=True)
    # What the held-out figure was measured on (``model_gate.basis``): scored takes with a
    # gold version, reviewed by several annotators, by one annotator alone, and their true
    # cuts; null for a model trained before it was kept.
    held_out_basis = models.JSONField(null=True, blank=True)
    refused = models.TextField(blank=True)
    # The reviewed takes the training left out (unreadable, too short), one line each.
    skipped = models.TextField(blank=True, default="")

    objects = CutModelQuerySet.as_manager()
    task = "retrain"
    input_error = "training: {error}"
    stopped_error = (
        "Training took too long and was stopped (time limit "
        "{settings.CUTROOM_RETRAIN_TIME_LIMIT} s, CUTROOM_RETRAIN_TIME_LIMIT); ask the "
        "administrators to raise the limit."
    )
    killed_error = (
        "{killed} The same examples would take as long again, so it is not retried; ask "
        "the administrators to raise the limit."
    )
    crashed_error = (
        "training failed with an internal error (reference {reference}); report this "
        "reference to the service's administrators"
    )
    abandoned_error = (
        "training started {attempts} times and never finished (the worker was killed or "
        "lost); the project keeps its previous model"
    )

    class Meta:
        ordering = ["-created_at", "-id"]
        constraints = [
            models.UniqueConstraint(fields=["project", "version"], name="one_cut_model_per_version"),
            # Requests made while one is waiting join it: one queued training per project.
            models.UniqueConstraint(
                fields=["project"], condition=Q(status="queued"), name="one_queued_training"
            ),
        ]

    def queued_behind(self):
        """The project's queued training: one training at a time per project, so it
        waits for this one to end."""
        return (
            ProjectCutModel.objects.filter(project_id=self.project_id, status="queued")
            .exclude(pk=self.pk)
            .first()
        )

    def __str__(self):
        return f"cut model v{self.version} of {self.project}" if self.version else (
            f"training of {self.project} ({self.status})")
