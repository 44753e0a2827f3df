"""Query-string parameters and request bodies. Each parser raises ``Invalid`` (a 400)
whose message names the parameter and the value at fault; a body that its serializer
refuses is a 400 naming each field."""

import math

from motionlib.errors import shorten
from segmentation.errors import Invalid


def int_param(request, name, default, low=None, high=None):
    """An integer query parameter between ``low`` and ``high``, or ``default`` if absent."""
    return _number(request, name, default, int, "an integer", low, high)


def float_param(request, name, low=None, high=None):
    """A number query parameter between ``low`` and ``high``, or None if absent."""
    return _number(request, name, None, float, "a number", low, high)


def bool_param(request, name):
    """true/1/yes or false/0/no, or None if absent."""
    raw = request.query_params.get(name)
    if raw is None or raw == "":
        return None
    if raw.lower() in ("true", "1", "yes"):
        return True
    if raw.lower() in ("false", "0", "no"):
        return False
    raise Invalid(f"{name}: must be true or false, got {shorten(raw)}")


# What a database integer holds (SQLite and PostgreSQL bigint): a larger filter is refused
# here instead of overflowing in the database driver.
INT_RANGE = (-(2**63), 2**63 - 1)


def _number(request, name, default, convert, kind, low, high):
    raw = request.query_params.get(name)
    if raw is None or raw == "":
        return default
    try:
        value = convert(raw)
    except ValueError:
        raise Invalid(f"{name}: must be {kind}, got {shorten(raw)}") from None
    if convert is int:
        low = INT_RANGE[0] if low is None else low
        high = INT_RANGE[1] if high is None else high
    elif not math.isfinite(value):
        raise Invalid(f"{name}: must be a finite number, got {shorten(raw)}")
    if low is not None and value < low or high is not None and value > high:
        shown = raw if len(raw) <= 40 else shorten(raw)
        raise Invalid(f"{name}: must be between {low} and {high}, got {shown}")
    return value


def body(request, serializer_class) -> dict:
    """The request body as ``serializer_class`` validates it (a 400 naming each bad field)."""
    serializer = serializer_class(data=request.data)
    serializer.is_valid(raise_exception=True)
    return serializer.validated_data
