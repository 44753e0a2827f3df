"""What makes two usernames the same account, and which new usernames are refused.

People type a name with stray spaces, in another case, or in a compatibility form
(full-width letters, ligatures, circled letters); all of these name one account.
``key(name)`` is that one form (stripped, NFKC, case-folded), and sign-in, the sign-in
throttle and account creation all compare keys, so no spelling of a locked name gets
round its lock and no new account can differ from an existing one by case or form only.

A new name may also not hold characters that show as nothing or pass for others:
format characters (zero-width spaces and joiners, direction marks), control and private
characters, spaces other than the plain one, letters of two scripts that share
look-alike letters (Latin, Greek, Cyrillic...), as in a Cyrillic "а" in "pаypal", or only
Cyrillic or Greek letters drawn like Latin ones (a Cyrillic "асе").
"""

import unicodedata

from django.contrib.auth import get_user_model

MAX_LENGTH = 150  # Django's own limit on usernames

# Scripts whose letters are mistaken for each other's; a name may use one of them.
LOOKALIKE_SCRIPTS = ("LATIN", "GREEK", "CYRILLIC", "ARMENIAN", "CHEROKEE", "COPTIC")
# Cyrillic and Greek letters drawn like Latin ones: a name made only of these (with
# digits and punctuation) reads as a Latin name that it is not ("асе" in Cyrillic).
LATIN_LOOKALIKES = set(
    "аеорсухіјѕһԁԛԝӏԜАВЕКМНОРСТХІЈЅҮ"  # Cyrillic
    "οαικνρτυχΑΒΕΖΗΙΚΜΝΟΡΤΥΧ"  # Greek
)
# Unicode categories never allowed: control, format, private use, surrogate, unassigned,
# and line or paragraph separators. Space separators other than " " are refused too.
REFUSED_CATEGORIES = {"Cc", "Cf", "Co", "Cs", "Cn", "Zl", "Zp"}


class UsernameError(ValueError):
    """A username that cannot be given to an account; the message says why."""


def key(name):
    """The form every spelling of ``name`` shares: stripped, NFKC, case-folded.

    Case folding can leave text that NFKC changes again (and NFKC can make spaces from
    other characters), hence the second pass.
    """
    name = unicodedata.normalize("NFKC", name.strip())
    return unicodedata.normalize("NFKC", name.casefold()).strip()


def clean(name):
    """``name`` as it is stored: stripped and in NFKC (case kept, for display).

    UsernameError names the first refused character, its position and code point.
    """
    typed = (name or "").strip()
    name = unicodedata.normalize("NFKC", typed)
    if not name or len(name) > MAX_LENGTH:
        raise UsernameError(f"must be 1 to {MAX_LENGTH} characters, got {len(name)}")
    # As typed as well as normalised: NFKC turns some of them into plain spaces or letters.
    _check_characters(typed)
    _check_characters(name)
    scripts = sorted({s for s in map(_script, name) if s in LOOKALIKE_SCRIPTS})
    if len(scripts) > 1:
        raise UsernameError(
            f"mixes letters of the {' and '.join(s.title() for s in scripts)} scripts, "
            "which look alike; use letters of one of them"
        )
    letters = [char for char in name if unicodedata.category(char).startswith("L")]
    if scripts and scripts != ["LATIN"] and set(letters) <= LATIN_LOOKALIKES:
        raise UsernameError(
            f"is written in {scripts[0].title()} letters that all look like Latin ones, so it "
            "reads as a Latin name it is not; use Latin letters, or others of your script"
        )
    return name


def _check_characters(name):
    for position, char in enumerate(name, 1):
        category = unicodedata.category(char)
        if category in REFUSED_CATEGORIES or (category == "Zs" and char != " "):
            label = unicodedata.name(char, "unnamed character")
            raise UsernameError(
                f"character {position} is U+{ord(char):04X} ({label}), which does not show "
                "or passes for another; use visible letters, digits, spaces and @.+-_"
            )


def _script(char):
    """The first word of the character's Unicode name ("LATIN", "CYRILLIC"...) for a letter."""
    if not unicodedata.category(char).startswith("L"):
        return None
    return unicodedata.name(char, "").split(" ", 1)[0] or None


def find_user(name):
    """The account ``name`` names, whatever its spelling, or None.

    The exact stored form is one indexed lookup; other spellings are looked up among the
    accounts the database finds case-insensitively, and compared by key.
    """
    users = get_user_model()._default_manager
    stored = unicodedata.normalize("NFKC", name.strip())
    if len(stored) > MAX_LENGTH:
        return None
    user = users.filter(username=stored).first()
    if user is not None:
        return user
    wanted = key(name)
    for candidate in users.filter(username__iexact=stored)[:20]:
        if key(candidate.username) == wanted:
            return candidate
    return None


def check_available(name, exclude=None):
    """UsernameError if an account other than ``exclude`` has a name with ``name``'s key.

    Compares keys of all usernames: creating accounts is a site admin's action, rare
    beside sign-ins, and the database cannot case-fold every script the same way.
    """
    wanted = key(name)
    users = get_user_model()._default_manager.all()
    if exclude is not None and exclude.pk is not None:
        users = users.exclude(pk=exclude.pk)
    for existing in users.values_list("username", flat=True).iterator():
        if key(existing) == wanted:
            raise UsernameError(f"an account named {existing!r} already exists")
