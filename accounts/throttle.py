"""Sign-in throttling, per username and per client address.

Failed sign-ins are rows of ``LoginFailure`` (the database is the one store every web
process shares, on the embedded default as in production). A username with
``CUTROOM_LOGIN_FAILURES_PER_USER`` failures within ``CUTROOM_LOGIN_WINDOW`` seconds, or
an address with ``CUTROOM_LOGIN_FAILURES_PER_ADDRESS``, is refused until the oldest of
those failures leaves the window (a sliding window). A refused attempt does not check
the password, so it costs no hashing, and it is not counted again.

Usernames are counted by ``usernames.key`` (every spelling of a name is one count), and
an attempt is counted before its password is checked (``admit``), under a row lock, so
that simultaneous guesses cannot all pass a count taken before any of them failed.
"""

import ipaddress
import math
from datetime import timedelta

from django.conf import settings
from django.db import transaction
from django.utils import timezone

from accounts import locks, usernames
from accounts.models import LoginFailure, digest

# Longer typed usernames are counted by their first this many characters.
MAX_TYPED = 20 * usernames.MAX_LENGTH
# The request attribute holding the failure rows ``admit`` recorded in advance.
ATTEMPT = "cutroom_sign_in_attempt"


def client_address(request):
    """The client's address: ``REMOTE_ADDR``, or, behind ``CUTROOM_TRUSTED_PROXIES``
    proxies, the address the outermost trusted proxy saw in ``X-Forwarded-For``.

    An IPv6 client is counted by its /64 network, since one host usually owns a whole one.
    """
    address = request.META.get("REMOTE_ADDR", "")
    proxies = settings.CUTROOM_TRUSTED_PROXIES
    if proxies:
        forwarded = [a.strip() for a in request.META.get("HTTP_X_FORWARDED_FOR", "").split(",")]
        forwarded = [a for a in forwarded if a]
        if forwarded:
            address = forwarded[-min(proxies, len(forwarded))]
    try:
        parsed = ipaddress.ip_address(address)
    except ValueError:
        return address[:100]
    if parsed.version == 6:
        if parsed.ipv4_mapped:
            return str(parsed.ipv4_mapped)
        return str(ipaddress.ip_network(f"{parsed}/64", strict=False))
    return str(parsed)


def _keys(request, username):
    """(key, limit) pairs this attempt counts against."""
    keys = []
    if username and usernames.key(username):
        name = usernames.key(username)
        keys.append((digest(f"user:{name}"), settings.CUTROOM_LOGIN_FAILURES_PER_USER))
    address = client_address(request)
    if address:
        keys.append((digest(f"addr:{address}"), settings.CUTROOM_LOGIN_FAILURES_PER_ADDRESS))
    return keys


def _window():
    return timedelta(seconds=settings.CUTROOM_LOGIN_WINDOW)


def _wait(keys, now):
    longest = timedelta(0)
    for key, limit in keys:
        recent = LoginFailure.objects.filter(key=key, at__gt=now - _window())
        times = list(recent.order_by("-at").values_list("at", flat=True)[:limit])
        if len(times) >= limit:
            # Refused until the limit-th most recent failure leaves the window.
            longest = max(longest, times[limit - 1] + _window() - now)
    return math.ceil(longest.total_seconds()) if longest else 0


def admit(request, username):
    """Let this sign-in attempt check its password, or say how long it must wait.

    Returns 0 and records the attempt as a failure in advance (a success takes it back,
    ``succeeded``), or the seconds to wait, recording nothing. Counting and recording
    happen under the keys' row locks, so of attempts arriving together no more are let
    through than the limits allow.
    """
    keys = _keys(request, username)
    now = timezone.now()
    # Old rows go first, outside the locks: deleting rows of other keys while holding
    # these would make attempts for different names wait on each other.
    LoginFailure.objects.filter(at__lte=now - _window()).delete()
    locks.forget_idle()
    with transaction.atomic():
        locks.hold(f"login:{key}" for key, _limit in keys)
        wait = _wait(keys, now)
        if wait:
            return wait
        rows = LoginFailure.objects.bulk_create(LoginFailure(key=key, at=now) for key, _ in keys)
    setattr(request, ATTEMPT, [row.pk for row in rows])
    return 0


def record_failure(request, username):
    """Count a failed sign-in (one ``admit`` counted already is not counted twice)."""
    if getattr(request, ATTEMPT, None) is not None:
        return
    now = timezone.now()
    LoginFailure.objects.filter(at__lte=now - _window()).delete()
    LoginFailure.objects.bulk_create(
        LoginFailure(key=key, at=now) for key, _limit in _keys(request, username)
    )


def succeeded(request, username):
    """A successful sign-in clears the username's failures and takes back the address's
    failure recorded in advance by ``admit`` (the address's earlier failures stay)."""
    forget_failures(username)
    attempt = getattr(request, ATTEMPT, None)
    if attempt:
        LoginFailure.objects.filter(pk__in=attempt).delete()
        setattr(request, ATTEMPT, [])


def forget_failures(username):
    """Clear the username's failures (whatever its spelling), not the address's."""
    if username:
        LoginFailure.objects.filter(key=digest(f"user:{usernames.key(username)}")).delete()


def username_of(data):
    """The username field of a sign-in form or JSON body, as text ('' if absent or odd).

    Stripped, as sign-in strips it, then cut to a length no username reaches even before
    NFKC (which can lengthen text up to 18 times), so a huge field costs no more than a
    long one. Cut first, 3,000 spaces before a name left nothing to count while sign-in
    found the account: every guess went uncounted and a locked account signed in.
    """
    value = data.get("username", "") if hasattr(data, "get") else ""
    return value.strip()[:MAX_TYPED] if isinstance(value, str) else ""
