"""How long the free text people send may be, in one place.

Every free-text field a request can carry is bounded: a field stored in a model column
takes that column's ``max_length`` (``text_limit``), and a comment kept in a text column
takes the bound its model field declares. Serializers declare the same bounds (an API
request longer than that is a 400 saying the bound), and the services check them again
(``check_text``) so that every other caller, the admin and the commands, is held to them
too. Without a bound a 100,000-character label name or a 5 MB comment would be stored and
sent back in every answer that shows it.
"""

import re
import unicodedata

from django.contrib.auth.models import AbstractUser

from accounts import usernames
from segmentation.errors import Invalid

# What a username may be (Django's user model), for the fields that name a person.
USERNAME_LENGTH = AbstractUser._meta.get_field("username").max_length


def text_limit(model, field):
    """The ``max_length`` of ``model.field``."""
    return model._meta.get_field(field).max_length


def check_text(field, value, limit):
    """``value`` if it has at most ``limit`` characters; else ``Invalid`` naming ``field``
    and the bound."""
    if len(value) > limit:
        raise Invalid(f"{field}: must be at most {limit} characters, got {len(value)}")
    return value


def check_name(field, value, limit):
    """``value``, a name others are shown (a project's, a label's), if it is within
    ``limit`` and holds nothing invisible, no direction mark and no look-alike letters
    (the rule usernames are held to, ``accounts.usernames.check_shown``); else ``Invalid``
    naming ``field`` and the character at fault."""
    check_text(field, value, limit)
    try:
        usernames.check_shown(value, words=True)
    except usernames.ShownNameError as exc:
        raise Invalid(f"{field}: {exc}") from None
    return value


# How much of a name a notice from someone else shows (an invitation's project name).
SHOWN_NAME = 60
HIDDEN = {"Cc", "Cf", "Co", "Cs", "Cn"}


def shown_name(name, limit=SHOWN_NAME):
    """``name`` as a notice from someone else shows it: characters that do not show
    (controls, format and direction marks) dropped, every run of space or line breaks one
    space, and cut to ``limit`` characters with an ellipsis, so that a name someone chose
    can name a project but cannot carry a page of instructions."""
    text = "".join(c for c in name if unicodedata.category(c) not in HIDDEN or c in "\n\t\r")
    text = re.sub(r"\s+", " ", text).strip()
    return text if len(text) <= limit else text[:limit - 1].rstrip() + "\u2026"
