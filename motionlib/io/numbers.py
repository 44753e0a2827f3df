"""Reading whitespace-separated decimal numbers exactly and at C speed.

The compiled reader (``motionlib/io/_parse.c``) gives bit for bit what ``float()`` gives for
decimals with an optional exponent (``-17.2528``, ``0``, ``+3.``, ``-2.51463e-014``): an
integer mantissa scaled by an exact power of ten in one correctly rounded operation, or
Python's own conversion for the rare number beyond that range. Anything else (``nan``,
``inf``, stray text, a line with another count) makes these functions return None, so the
caller can fall back to a careful line-by-line parse that says what is wrong and where.
"""

from __future__ import annotations

import numpy as np

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


def token_bounds(b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Start (inclusive) and end (exclusive) byte index of each whitespace-separated token.

    Bytes up to 32 (space, tab, CR, LF and other controls) separate tokens.
    """
    if b.size == 0:
        return np.zeros(0, np.intp), np.zeros(0, np.intp)
    tok = b > 32
    # Edge i lies between bytes i-1 and i; the text is padded with whitespace at both ends so
    # edges alternate start, end, start, end...
    edge = np.empty(b.size + 1, bool)
    edge[0], edge[-1] = tok[0], tok[-1]
    np.not_equal(tok[1:], tok[:-1], out=edge[1:-1])
    edges = np.flatnonzero(edge)
    return edges[0::2], edges[1::2]


def token_values(b: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> np.ndarray | None:
    """Value of every token ``b[starts[i]:ends[i]]``, or None if one is not a finite decimal.

    Parameters
    ----------
    b : ndarray of uint8
        The text.
    starts, ends : ndarray of int
        Byte bounds of the tokens to read (any subset of the tokens of ``b``).

    Returns
    -------
    ndarray of float64, shape (n_tokens,), or None
    """
    starts = np.ascontiguousarray(starts, dtype=np.intp)
    ends = np.ascontiguousarray(ends, dtype=np.intp)
    out = np.empty(starts.size)
    return out if _parse.read_tokens(np.ascontiguousarray(b), starts, ends, out) < 0 else None
