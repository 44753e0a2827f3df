"""Changing one's password, and a site admin's reset of someone's.

A reset gives a one-time password (``segmentation.models.OneTimePassword``): signed in
with it, its owner must first choose their own (``middleware``, ``views.new_password``).
Either way the new password ends the account's other sessions (Django signs each session
with the password's hash) and revokes its API tokens (``signals``): whoever had the old
password, or a session or token made with it, is signed out.
"""

import secrets

from django.contrib.auth import password_validation
from django.core.exceptions import ValidationError
from django.db import transaction

from segmentation.models import OneTimePassword


class PasswordError(ValueError):
    """A password change that cannot be made; ``field`` is the field at fault."""

    def __init__(self, field, message):
        super().__init__(f"{field}: {message}")
        self.field = field


def check_new(user, password):
    """PasswordError naming what makes ``password`` too weak for ``user``."""
    try:
        password_validation.validate_password(password, user)
    except ValidationError as exc:
        raise PasswordError("new_password", " ".join(exc.messages)) from None


def change(user, current, new):
    """Set ``user``'s password to ``new`` if ``current`` is their password now.

    The caller counts the check of ``current`` against the sign-in throttle, since a
    session left open must not become a way to guess the password.
    """
    if not user.check_password(current):
        raise PasswordError("current_password", "this is not your current password")
    if current == new:
        raise PasswordError("new_password", "must differ from the current password")
    check_new(user, new)
    choose(user, new)


def choose(user, new):
    """Set ``user``'s password to ``new``, one they chose: no longer a one-time password."""
    with transaction.atomic():
        user.set_password(new)
        user.save()
        OneTimePassword.objects.filter(user=user).delete()


def is_one_time(user):
    """Whether ``user`` still has a password someone else made for them."""
    return OneTimePassword.objects.filter(user=user).exists()


def can_reset(actor):
    """Site admins, who may change any account in the admin anyway."""
    return actor.has_perm("auth.change_user")


def reset(user):
    """Give ``user`` a new one-time password (returned; shown once) to change at sign-in."""
    password = secrets.token_urlsafe(12)
    with transaction.atomic():
        user.set_password(password)
        user.save()
        OneTimePassword.objects.update_or_create(user=user)
    return password
