"""Reading whitespace-separated decimal numbers exactly and at C speed.

The compiled reader (``motionlib/io/_parse.c``) gives bit for bit what ``float()`` gives for
decimals with an optional exponent (``-17.2528``, ``0``, ``+3.``, ``-2.51463e-014``): an
integer mantissa scaled by an exact power of ten in one correctly rounded operation, or
Python's own conversion for the rare number beyond that range. Anything else (``nan``,
``inf``, stray text, a line with another count) makes these functions return None, so the
caller can fall back to a careful line-by-line parse that says what is wrong and where.
"""

from __future__ import annotations

import math

import numpy as np

from motionlib.errors import CaptureError, shorten
from motionlib.io import _parse


def read_rows(data: bytes, offset: int, n_rows: int, row_length: int) -> np.ndarray | None:
    """The numbers of ``data[offset:]`` as (n_rows, row_length), or None.

    Parameters
    ----------
    data : bytes
        ASCII text; blank lines are skipped, spaces, tabs and CR separate numbers.
    offset : int
        Byte where the rows start.
    n_rows, row_length : int
        The shape the text must have: exactly ``n_rows`` non-blank lines of exactly
        ``row_length`` numbers each.

    Returns
    -------
    ndarray of float64, shape (n_rows, row_length), or None
        None when the text has another shape or a token is not a finite decimal.
    """
    if row_length <= 0:
        return None
    out = np.empty((n_rows, row_length))
    return out if _parse.read_rows(data, offset, out, row_length) == n_rows else None


def finite_value(token: str, before: str, after: str, path, line: int) -> float:
    """``float(token)`` for the careful line-by-line readers, or a CaptureError at path:line.

    The message names the token as ``before + repr(token) + after`` (e.g. ``"frame 3, value
    2: "`` and ``""``, or ``"value "`` and ``" of bone 'root'"``), then says what is wrong.
    """
    try:
        value = float(token)
    except ValueError:
        raise CaptureError(f"{before}{shorten(token)}{after} is not a number", path=path,
                           line=line) from None
    if not math.isfinite(value):
        raise CaptureError(f"{before}{shorten(token)}{after} is not a finite number", path=path,
                           line=line)
    return value
