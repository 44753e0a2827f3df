"""Team management: members' roles, removal, and accounts made by site admins.

Every change that could leave a project without an admin locks the project row first, so
two simultaneous demotions (or removals) of its last two admins run one after the other
and the second sees that only one admin is left, and is refused.
"""

import secrets

from django.contrib.auth import get_user_model
from django.db import IntegrityError, transaction

from segmentation import usernames
from segmentation.errors import Invalid, NotAllowed
from segmentation.models import Membership, OneTimePassword, Project

ROLES = ("annotator", "reviewer", "admin")


def _locked(project):
    return Project.objects.select_for_update().get(pk=project.pk)


def _keep_an_admin(project, membership, new_role):
    if membership.role != "admin" or new_role == "admin":
        return
    others = project.memberships.filter(role="admin").exclude(pk=membership.pk)
    if not others.exists():
        raise Invalid(f"role: {membership.user.username!r} is the project's last admin; "
                      "make someone else admin first")


def do_change_role(project, membership, role):
    if role not in ROLES:
        raise Invalid(f"role: must be one of {', '.join(ROLES)}, got {role!r}")
    with transaction.atomic():
        _locked(project)
        membership = Membership.objects.select_related("user").get(pk=membership.pk)
        _keep_an_admin(project, membership, role)
        membership.role = role
        membership.save(update_fields=["role"])
    return membership


def do_remove_member(project, membership):
    """Take someone out of the project; their reviews and assignments stay on record."""
    with transaction.atomic():
        _locked(project)
        membership = Membership.objects.select_related("user").get(pk=membership.pk)
        _keep_an_admin(project, membership, None)
        membership.delete()


def can_create_accounts(user):
    """Only site admins make accounts: they may list accounts anyway, so a clash on a
    username tells them nothing new. A project admin could otherwise probe which
    usernames exist, which invitations are designed not to reveal."""
    return user.has_perm("auth.add_user")


def do_create_account(project, actor, username, role):
    """A new account with a one-time password, made a member of the project.

    Returns (membership, password); the password is not stored anywhere readable and is
    shown once. Signed in with it, the person must first choose their own.
    """
    if not can_create_accounts(actor):
        raise NotAllowed("Only site admins create accounts; invite an existing user instead.")
    if role not in ROLES:
        raise Invalid(f"role: must be one of {', '.join(ROLES)}, got {role!r}")
    try:
        username = usernames.clean(username)
    except usernames.UsernameError as exc:
        raise Invalid(f"username: {exc}") from None
    password = secrets.token_urlsafe(12)
    try:
        with transaction.atomic():
            _check_available(username)
            user = get_user_model().objects.create_user(username, password=password)
            OneTimePassword.objects.create(user=user)
            membership = Membership.objects.create(project=project, user=user, role=role)
    except IntegrityError:
        raise Invalid(f"username: an account named {username!r} already exists; invite it") from None
    return membership, password


def _check_available(username):
    """Invalid if an account's name differs from ``username`` only in case or form."""
    try:
        usernames.check_available(username)
    except usernames.UsernameError as exc:
        raise Invalid(f"username: {exc}; invite it") from None
