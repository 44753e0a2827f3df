"""Adding people to projects: by invitation, which the person accepts or declines.

A project admin's "add member" must neither reveal whether an account exists (anyone can
create a project, so it would enumerate usernames) nor put someone into a stranger's
project. So it changes the role of someone already a member (the admin sees the members
anyway) and otherwise invites the username, whether or not an account has it; only a
site admin (who may see accounts) is told that no account has that name.

Invitations are limited per inviter (CUTROOM_INVITATIONS_PER_HOUR) and per invited
username (CUTROOM_INVITATIONS_PER_INVITEE in a day, from everyone), so nobody can flood a
person's list of invitations (each shows a project name of the inviter's choosing). Both
are counted under row locks in the transaction that makes the invitation.
"""

import unicodedata
from datetime import timedelta

from django.conf import settings
from django.contrib.auth import get_user_model
from django.db import transaction
from django.utils import timezone

from accounts import locks
from segmentation.errors import Invalid, NotAllowed, TooManyRequests
from segmentation.models import Invitation
from segmentation.services import quotas
from segmentation.services.projects import do_set_member

USERNAME_MAX = 150  # Django's own limit on usernames


def can_see_accounts(user):
    """Site admins, who may list accounts in the admin anyway, learn whether one exists."""
    return user.has_perm("auth.view_user")


def do_add_member(project, actor, username, role):
    """A member's new role (a ``Membership``), or an ``Invitation`` for anyone else.

    The invitation is made the same way whether or not an account named ``username``
    exists, so nothing the caller sees differs (unless ``can_see_accounts(actor)``).
    Inviting a username again replaces its pending invitation. The username is taken
    stripped and in NFKC, the form account names are stored in.
    """
    username = unicodedata.normalize("NFKC", (username or "").strip())
    if not username or len(username) > USERNAME_MAX:
        raise Invalid(f"username: must be 1 to {USERNAME_MAX} characters, got {len(username)}")
    with transaction.atomic():
        if project.memberships.filter(user__username=username).exists():
            return do_set_member(project, username, role)
        _check_invitation_rates(project, actor, username)
        users = get_user_model().objects
        if can_see_accounts(actor) and not users.filter(username=username).exists():
            raise Invalid(f"username: no user named {username!r}")
        now = timezone.now()
        invitation, _ = Invitation.objects.update_or_create(
            project=project, username=username, status="pending",
            defaults={"role": role, "invited_by": actor, "created_at": now,
                      "expires_at": now + timedelta(days=settings.CUTROOM_INVITATION_DAYS)},
        )
    return invitation


def _check_invitation_rates(project, actor, username):
    """TooManyRequests past the inviter's hourly or the invitee's daily limit. The
    refusal reads the same whether or not an account has the username."""
    quotas.lock(project, actor)
    locks.hold([f"invitee:{username}"])
    now = timezone.now()
    hour, day = now - timedelta(hours=1), now - timedelta(days=1)
    limit = settings.CUTROOM_INVITATIONS_PER_HOUR
    made = Invitation.objects.filter(invited_by=actor, created_at__gte=hour)
    if limit and made.count() >= limit:
        raise TooManyRequests(
            f"username: you sent {limit} invitations in the last hour; the limit is {limit} "
            f"per hour (CUTROOM_INVITATIONS_PER_HOUR); try again in {_wait(made, hour)} s",
            retry_after=_wait(made, hour),
        )
    limit = settings.CUTROOM_INVITATIONS_PER_INVITEE
    received = Invitation.objects.filter(username=username, created_at__gte=day)
    if limit and received.exclude(project=project, status="pending").count() >= limit:
        raise TooManyRequests(
            f"username: {username!r} was invited {limit} times in the last day, the limit "
            f"(CUTROOM_INVITATIONS_PER_INVITEE); try again in {_wait(received, day)} s",
            retry_after=_wait(received, day),
        )


def _wait(invitations, since):
    """Seconds until the oldest of ``invitations`` made after ``since`` stops counting."""
    oldest = invitations.order_by("created_at").values_list("created_at", flat=True).first()
    return max(1, int((oldest - since).total_seconds()) + 1) if oldest else 60


def do_accept_invitation(invitation, user):
    """Join the project with the invited role; the invitation records who and when.

    The inviter must still be an admin of the project: an invitation carries their
    authority, and one made by an admin since removed or demoted (or whose account is
    gone) is refused (NotAllowed), not accepted with the role they could once give.
    """
    with transaction.atomic():
        invitation = _still_pending(invitation, user)
        _check_inviter(invitation)
        membership = do_set_member(invitation.project, user.get_username(), invitation.role)
        _answer(invitation, user, "accepted")
    return membership


def do_decline_invitation(invitation, user):
    with transaction.atomic():
        invitation = _still_pending(invitation, user)
        _answer(invitation, user, "declined")
    return invitation


def do_cancel_invitation(invitation, admin):
    """A project admin withdraws a pending invitation (it stays on record, cancelled)."""
    with transaction.atomic():
        invitation = Invitation.objects.select_for_update().get(pk=invitation.pk)
        if invitation.status != "pending":
            raise Invalid(f"status: the invitation is already {invitation.status}")
        _answer(invitation, admin, "cancelled")
    return invitation


def _still_pending(invitation, user):
    """The invitation re-read under a row lock, if it is still the user's to answer."""
    locked = Invitation.objects.select_for_update().for_user(user).filter(pk=invitation.pk).first()
    if locked is None:
        raise Invalid("status: this invitation was already answered, cancelled or has expired")
    return locked


def _check_inviter(invitation):
    inviter = invitation.invited_by
    if inviter is not None and invitation.project.role_of(inviter) == "admin":
        return
    who = f"{inviter.get_username()}, who is" if inviter is not None else "an account that is"
    raise NotAllowed(f"this invitation to {invitation.project.name!r} was made by {who} no "
                     "longer an admin of the project; ask one of its admins to invite you again")


def _answer(invitation, user, status):
    invitation.status = status
    invitation.answered_by = user
    invitation.answered_at = timezone.now()
    invitation.save(update_fields=["status", "answered_by", "answered_at"])
