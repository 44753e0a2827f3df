"""What makes two usernames the same account, and which new usernames are refused.

People type a name with stray spaces, in another case, or in a compatibility form
(full-width letters, ligatures, circled letters); all of these name one account.
``key(name)`` is that one form (stripped, NFKC, case-folded), stored for every account
(``models.UsernameKey``); sign-in, the sign-in throttle and account creation all compare
keys, so no spelling of a locked name gets round its lock and no new account can differ
from an existing one by case or form only.

A new name may also not hold characters that show as nothing or pass for others:
format characters (zero-width spaces and joiners, direction marks), control and private
characters, spaces other than the plain one, letters of two scripts that share
look-alike letters (Latin, Greek, Cyrillic...), as in a Cyrillic "а" in "pаypal", or only
Cyrillic or Greek letters drawn like Latin ones (a Cyrillic "асе"). ``check_shown`` is
that rule alone; the names people see beside usernames (projects, labels) are held to it.
"""

import hashlib
import unicodedata

from django.contrib.auth import get_user_model

from accounts.models import UsernameKey

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


USERNAME_HINT = "use visible letters, digits, spaces and @.+-_"
NAME_HINT = "use visible letters, digits, punctuation and plain spaces"


class ShownNameError(ValueError):
    """A name shown to others that holds characters that show as nothing or pass for
    others; the message says which."""


class UsernameError(ShownNameError):
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
    try:
        check_shown(typed, USERNAME_HINT)
    except ShownNameError as exc:
        raise UsernameError(str(exc)) from None
    return name


def check_shown(text, hint=NAME_HINT, words=False):
    """Refuse ``text``, a name shown to other people, if it holds characters that show as
    nothing or pass for others (see the module docstring).

    The same rule holds account names and the names others see beside them (projects,
    labels). With ``words``, letters of two look-alike scripts are refused within a word
    only: "Студия MoCap" is a fair project name, "pаypal" (a Cyrillic "а") is not.
    ``ShownNameError`` names the first refused character, its position and code point.
    """
    # As typed as well as normalised: NFKC turns some of them into plain spaces or letters.
    _check_characters(text, hint)
    name = unicodedata.normalize("NFKC", text)
    _check_characters(name, hint)
    for part in name.split() if words else [name]:
        scripts = sorted({s for s in map(_script, part) if s in LOOKALIKE_SCRIPTS})
        if len(scripts) > 1:
            where = f"the word {part!r} " if words else ""
            raise ShownNameError(
                f"{where}mixes letters of the {' and '.join(s.title() for s in scripts)} "
                "scripts, which look alike; use letters of one of them"
            )
    scripts = sorted({s for s in map(_script, name) if s in LOOKALIKE_SCRIPTS})
    letters = [char for char in name if unicodedata.category(char).startswith("L")]
    if scripts and "LATIN" not in scripts and set(letters) <= LATIN_LOOKALIKES:
        raise ShownNameError(
            f"is written in {scripts[0].title()} letters that all look like Latin ones, so it "
            "reads as a Latin name it is not; use Latin letters, or others of your script"
        )


def _check_characters(name, hint):
    for position, char in enumerate(name, 1):
        category = unicodedata.category(char)
        if category in REFUSED_CATEGORIES or (category == "Zs" and char != " "):
            label = unicodedata.name(char, "unnamed character")
            raise ShownNameError(
                f"character {position} is U+{ord(char):04X} ({label}), which does not show "
                f"or passes for another; {hint}"
            )


def _script(char):
    """The first word of the character's Unicode name ("LATIN", "CYRILLIC"...) for a letter."""
    if not unicodedata.category(char).startswith("L"):
        return None
    return unicodedata.name(char, "").split(" ", 1)[0] or None


def digest(name):
    """The stored form of ``key(name)`` (``UsernameKey.digest``): its SHA-256, in hex."""
    return hashlib.sha256(key(name).encode("utf-8", "surrogatepass")).hexdigest()


def find_user(name):
    """The account ``name`` names, whatever its spelling, or None.

    The exact stored form first, then the key: two indexed lookups.
    """
    users = get_user_model()._default_manager
    stored = unicodedata.normalize("NFKC", name.strip())
    if len(stored) > MAX_LENGTH:
        return None
    user = users.filter(username=stored).first()
    if user is not None:
        return user
    return users.filter(username_key__digest=digest(name)).first()


def check_available(name, exclude=None):
    """UsernameError if an account other than ``exclude`` has a name with ``name``'s key."""
    users = get_user_model()._default_manager.filter(username_key__digest=digest(name))
    if exclude is not None and exclude.pk is not None:
        users = users.exclude(pk=exclude.pk)
    existing = users.values_list("username", flat=True).first()
    if existing is not None:
        raise UsernameError(f"an account named {existing!r} already exists")


def remember(user, created):
    """Store the key of ``user``'s name after the account is saved.

    A new account's row is inserted as is: when another account took the same key a
    moment earlier, the unique index raises IntegrityError and the creation (in its
    transaction) is undone. A renamed account whose new name clashes with an older
    account's keeps no key (it signs in by its exact name only).
    """
    wanted = digest(user.username)
    if created:
        UsernameKey.objects.create(user=user, digest=wanted)
        return
    if UsernameKey.objects.filter(user=user, digest=wanted).exists():
        return
    if UsernameKey.objects.filter(digest=wanted).exclude(user=user).exists():
        wanted = None
    UsernameKey.objects.update_or_create(user=user, defaults={"digest": wanted})
