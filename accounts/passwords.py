"""Changing one's password, and a site admin's reset of someone's.

Either way the new password ends the account's other sessions (Django signs each session
with the password's hash) and revokes its API tokens (``signals``): whoever had the old
password, or a session or token made with it, is signed out.
"""

import secrets

from django.contrib.auth import password_validation
from django.core.exceptions import ValidationError


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
    user.set_password(new)
    user.save()


def can_reset(actor):
    """Site admins, who may change any account in the admin anyway."""
    return actor.has_perm("auth.change_user")


def reset(user):
    """Give ``user`` a new one-time password (returned; shown once) to change at sign-in."""
    password = secrets.token_urlsafe(12)
    user.set_password(password)
    user.save()
    return password
