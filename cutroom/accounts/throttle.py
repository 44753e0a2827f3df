"""Sign-in throttling, per username and per client address.

Failed sign-ins are rows of ``LoginFailure`` (the database is the one store every web
process shares, on the embedded default as in production). A username with
``CUTROOM_LOGIN_FAILURES_PER_USER`` failures within ``CUTROOM_LOGIN_WINDOW`` seconds, or
an address with ``CUTROOM_LOGIN_FAILURES_PER_ADDRESS``, is refused until the oldest of
those failures leaves the window (a sliding window). A refused attempt does not check
the password, so it costs no hashing, and it is not counted again.
"""

import ipaddress
import math
from datetime import timedelta

from django.conf import settings
from django.utils import timezone

from cutroom.accounts.models import LoginFailure, digest


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
    if username:
        name = username.casefold()
        keys.append((digest(f"user:{name}"), settings.CUTROOM_LOGIN_FAILURES_PER_USER))
    address = client_address(request)
    if address:
        keys.append((digest(f"addr:{address}"), settings.CUTROOM_LOGIN_FAILURES_PER_ADDRESS))
    return keys


def _window():
    return timedelta(seconds=settings.CUTROOM_LOGIN_WINDOW)


def wait_seconds(request, username):
    """Seconds before this username may try again from this address; 0 if it may now."""
    now = timezone.now()
    longest = timedelta(0)
    for key, limit in _keys(request, username):
        recent = LoginFailure.objects.filter(key=key, at__gt=now - _window())
        times = list(recent.order_by("-at").values_list("at", flat=True)[:limit])
        if len(times) >= limit:
            # Refused until the limit-th most recent failure leaves the window.
            longest = max(longest, times[limit - 1] + _window() - now)
    return math.ceil(longest.total_seconds()) if longest else 0


def record_failure(request, username):
    now = timezone.now()
    LoginFailure.objects.filter(at__lte=now - _window()).delete()
    LoginFailure.objects.bulk_create(
        LoginFailure(key=key, at=now) for key, _limit in _keys(request, username)
    )


def forget_failures(username):
    """A successful sign-in clears the username's failures (not the address's)."""
    if username:
        LoginFailure.objects.filter(key=digest(f"user:{username.casefold()}")).delete()


def username_of(data):
    """The username field of a sign-in form or JSON body, as text ('' if absent or odd)."""
    value = data.get("username", "") if hasattr(data, "get") else ""
    return value if isinstance(value, str) else ""
