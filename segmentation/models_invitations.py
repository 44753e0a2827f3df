"""Invitations to join a project.

Nobody is placed in a project without saying yes: a project admin invites a *username*,
and the account of that name sees the invitation and accepts or declines it. An
invitation names a username rather than a user so that inviting a name no account has
looks, to the inviter, exactly like inviting a person: same answer, same pending list.
That keeps usernames from being enumerated through projects anyone can create.

Rows are never deleted (short of deleting the project): they are the record of who
invited whom to what role, when, and who accepted, declined or cancelled it, when.
"""

from django.conf import settings
from django.db import models
from django.db.models import Q
from django.utils import timezone

from segmentation.models import ROLES


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

    project = models.ForeignKey("segmentation.Project", models.CASCADE, related_name="invitations")
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
