"""How long the free text people send may be, in one place.

Every free-text field a request can carry is bounded: a field stored in a model column
takes that column's ``max_length`` (``text_limit``), and a comment kept in a text column
takes the bound its model field declares. Serializers declare the same bounds (an API
request longer than that is a 400 saying the bound), and the services check them again
(``check_text``) so that every other caller, the admin and the commands, is held to them
too. Without a bound a 100,000-character label name or a 5 MB comment would be stored and
sent back in every answer that shows it.
"""

from django.contrib.auth.models import AbstractUser

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
