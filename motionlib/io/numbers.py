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

from motionlib import threads
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
    if len(data) - offset >= PARALLEL_BYTES and threads.threads() > 1:
        return out if _read_halves(data, offset, out, row_length) == n_rows else None
    return out if _parse.read_rows(data, offset, out, row_length) == n_rows else None


# Text from which reading is worth splitting over two threads (~30 ms of parsing).
PARALLEL_BYTES = 4 << 20


def _read_halves(data: bytes, offset: int, out: np.ndarray, row_length: int) -> int:
    """``_parse.read_rows`` of ``data[offset:]`` as two halves read at once, split at a line
    end: the first half's rows from ``out[0]``, the second's after as many rows as the first
    half has lines (blank lines are not rows: then the second half's rows move up). The
    row count, or -1 as ``read_rows`` gives."""
    middle = data.find(b"\n", offset + (len(data) - offset) // 2)
    if middle < 0:
        return _parse.read_rows(data, offset, out, row_length)
    lines = data.count(b"\n", offset, middle + 1)
    if lines > len(out):  # more lines than rows: the one-thread read says what is wrong
        return _parse.read_rows(data, offset, out, row_length)
    first, second = threads.run_all([
        lambda: _parse.read_rows(data, offset, out[:lines], row_length, middle + 1),
        lambda: _parse.read_rows(data, middle + 1, out[lines:], row_length),
    ])
    if first < 0 or second < 0:
        return -1
    if first < lines:
        out[first:first + second] = out[lines:lines + second].copy()
    return first + second


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
