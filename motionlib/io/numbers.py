"""Vectorised parsing of whitespace-separated numbers, with tokens-per-line counts.

``float()`` per token or ``np.loadtxt`` cost 40-100 ms for a 4,600-frame BVH; this parser works
on the raw bytes with numpy passes over all tokens at once and gives bit-identical results to
``float()`` for decimals with an optional exponent (``-17.2528``, ``0``, ``+3.``,
``-2.51463e-014``): the digits are summed as an exact integer and scaled by a power of ten in
one correctly rounded operation (the rare token beyond that exact range, with more than ~15
digits or a power of ten beyond ±22, goes through ``float()``). Anything that is not such a
number (``nan``, ``inf``, stray text) makes it return None so the caller can fall back to a
careful line-by-line parse that can also say what is wrong and where. BVH text is parsed in
chunks of whole lines so the temporaries stay small (peak memory about the size of the text
plus the result) and in cache.
"""

from __future__ import annotations

import numpy as np

_POW10 = 10.0 ** np.arange(64)
_DOT_SCALE = np.concatenate([[1.0], _POW10[:-1]])  # by dot position from the right: 10**(p-1)
_INTEGER_SCALE = np.concatenate([[_POW10[-1]], _POW10[1:]])  # 10**p, and 10**63 for no dot
_NINE_TENTHS_SCALE = np.concatenate([[0.0], 9 * _POW10[:-1]])  # 9 * 10**(p-1), exact
_EXACT = 2.0**53  # integers below this are exact in float64
_MAX_TOKEN = 32
_MAX_POWER = 22  # 10**22 is the largest power of ten that float64 holds exactly
CHUNK_BYTES = 1 << 18


def parse_decimal_lines(data: bytes, offset: int = 0,
                        chunk_bytes: int = CHUNK_BYTES) -> tuple[np.ndarray, np.ndarray] | None:
    """Parse ``data[offset:]`` as lines of numbers.

    Parameters
    ----------
    data : bytes
        ASCII text.
    offset : int
        Byte where the numbers start.
    chunk_bytes : int
        Work on about this many bytes (whole lines) at a time.

    Returns
    -------
    (values, per_line) or None
        ``values`` float64 of shape (n_tokens,) in reading order; ``per_line`` the number of
        tokens on each line (blank lines included, as 0). None when some token is not a number
        this parser reads exactly.
    """
    values, counts = [], []
    pos = offset
    while pos < len(data):
        end = data.find(b"\n", min(pos + chunk_bytes, len(data)) - 1)
        end = len(data) if end < 0 else end + 1
        b = np.frombuffer(data, dtype=np.uint8, count=end - pos, offset=pos)
        starts, ends = token_bounds(b)
        chunk_values = token_values(b, starts, ends)
        if chunk_values is None:
            return None
        values.append(chunk_values)
        newlines = np.flatnonzero(b == 10)
        counts.append(np.diff(np.searchsorted(starts, newlines), prepend=0, append=starts.size))
        pos = end
    if not values:
        return np.zeros(0), np.zeros(0, np.intp)
    return np.concatenate(values), np.concatenate(counts)


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


class _Walk:
    """Per-token state of the backward walk (see token_values), in walking order."""

    def __init__(self, n: int):
        self.total = np.zeros(n)        # digits weighted by byte position from the right
        self.dot = np.zeros(n, np.uint8)      # byte position of the dot from the right, 0 = none
        self.e = np.zeros(n, np.uint8)        # same for 'e' / 'E'
        self.inner_sign = np.zeros(n, np.uint8)  # same for a sign that is not in front
        self.exp_negative = np.zeros(n, bool)
        self.count = np.zeros(n, np.uint8)    # dots + exponent markers + inner signs seen
        self.bad = np.zeros(n, bool)
        self.digits = np.zeros(n, np.uint8)   # plain walk: digits seen
        self.scratch = np.empty(n)            # plain walk: one pass's weighted digits


def token_values(b: np.ndarray, starts: np.ndarray, ends: np.ndarray, *,
                 plain: bool | None = None) -> np.ndarray | None:
    """Value of every token, or None if one of them is not a number read exactly here.

    All tokens are walked from their last byte backwards in lockstep, longest first so that
    pass k only touches the tokens that still have a k-th byte (a prefix, no masking). Digits
    are summed with the weight of their byte position (10**(k-1) for the k-th byte from the
    right) so a pass multiplies by one scalar; the positions of the dot, the exponent marker
    and its sign are recorded and corrected for afterwards. Text without exponents (BVH as
    written by most tools) takes a lighter walk first, validated by counting digits.

    Parameters
    ----------
    b : ndarray of uint8
        The text.
    starts, ends : ndarray of int
        Byte bounds of the tokens to read (any subset of the tokens of ``b``).
    plain : bool, optional
        True: the tokens have no exponents (decline otherwise); False: use the full walk
        (exponents allowed); None (default): try the light walk, then the full one.

    Returns
    -------
    ndarray of float64, shape (n_tokens,), or None
    """
    if starts.size == 0:
        return np.zeros(0)
    length = ends - starts
    longest = int(length.max())
    if longest > _MAX_TOKEN:
        return None
    length = length.astype(np.uint8)
    order = np.argsort(length, kind="stable")[::-1]  # radix sort of small ints: cheap
    walked = length[order]  # lengths, longest first
    # at_least[k]: how many tokens have a k-th byte; they are the first ones in `order`.
    at_least = np.searchsorted(-walked.astype(np.int16), -np.arange(longest + 2), side="right")
    first = b[starts][order]
    found = None
    if plain is not False:  # most text has no exponents: try the lighter walk first
        w = _walk(b, ends[order], longest, at_least, plain=True)
        found = _finish_plain(w, walked, first)
    if found is None and not plain:
        w = _walk(b, ends[order], longest, at_least, plain=False)
        found = _finish(w, walked, first)
    if found is None:
        return None
    return _unsort(found, order, b, starts, ends)


def _walk(b, ends, longest: int, at_least, *, plain: bool) -> _Walk:
    """One pass per byte position from the right; pass k covers the at_least[k] tokens (in
    walking order, longest first) that have a k-th byte."""
    w = _Walk(ends.size)
    pos = ends.astype(np.intp, copy=False)  # a fresh gather: ours to change
    for k in range(1, longest + 1):
        m = int(at_least[k])
        p = pos[:m]
        p -= 1
        if plain:
            _plain_step(w, b[p], m, k)
        else:
            _step(w, b[p], m, int(at_least[k + 1]), k)
    return w


def _plain_step(w: _Walk, c, m: int, k: int) -> None:
    """Pass k for text without exponents: digits and dots (checked by counting afterwards)."""
    d = c - np.uint8(48)
    isdig = d < 10
    d *= isdig
    w.digits[:m] += isdig
    np.multiply(d, _POW10[k - 1], out=w.scratch[:m])
    w.total[:m] += w.scratch[:m]
    np.copyto(w.dot[:m], k, where=c == 46)


def _finish_plain(w: _Walk, length, first):
    """(values, inexact) after a plain walk, or None if a token is not a plain decimal.

    A plain decimal is digits, at most one dot and a leading sign: its length is exactly its
    digits + dot + sign, which any other byte (a second dot, an inner sign, a letter) breaks.
    """
    has_sign = (first == 45) | (first == 43)
    has_dot = w.dot > 0
    if np.any(length != w.digits + has_dot + has_sign) or not np.all(w.digits):
        return None
    # With the dot at byte position p, total = I * 10**p + F (integer part I, fraction digits
    # F < 10**(p-1), the dot weighing 0), while the mantissa is I * 10**(p-1) + F, that is
    # total - 9 * I * 10**(p-1): exact integer arithmetic while total < 2**53. Without a dot,
    # the scale 10**63 makes I = 0.
    dot = w.dot.astype(np.intp)
    integer = w.total / _INTEGER_SCALE.take(dot)
    np.floor(integer, out=integer)
    integer *= _NINE_TENTHS_SCALE.take(dot)
    mantissa = np.subtract(w.total, integer, out=integer)
    mantissa /= _DOT_SCALE.take(dot)
    np.negative(mantissa, out=mantissa, where=first == 45)
    return mantissa, w.total >= _EXACT


def _below(total: np.ndarray, digits: np.ndarray) -> np.ndarray:
    """``total mod 10**digits`` for exact integers below 2**53 (floor of the quotient is exact
    there, and is much faster than fmod)."""
    scale = _POW10[digits]
    return total - np.floor(total / scale) * scale


def _drop_marker(total, right_digits, has_marker):
    """Remove a zero-weight marker byte sitting left of ``right_digits`` digits: the digits left
    of it were weighted ten times too much."""
    right = _below(total, right_digits)
    return np.where(has_marker, right + (total - right) / 10.0, total)


def _step(w: _Walk, c, m: int, inner_end: int, k: int) -> None:
    """Pass k over the first m tokens (those with a k-th byte); the first ``inner_end`` of them
    are longer than k, so byte k is not their first byte."""
    d = c - np.uint8(48)
    isdig = d < 10
    isdot = c == 46
    ise = (c == 101) | (c == 69)
    issign = (c == 45) | (c == 43)
    w.bad[:m] |= ~(isdig | isdot | ise | issign)
    d *= isdig
    w.total[:m] += d * _POW10[k - 1]
    if isdot.any():
        w.dot[:m][isdot] = k
        w.count[:m] += isdot
    if ise.any():
        w.e[:m][ise] = k
        w.count[:m] += ise
        w.bad[:m] |= ise & (w.dot[:m] > 0)  # a dot in the exponent
    inner = issign[:inner_end]
    if inner.any():
        w.inner_sign[:inner_end][inner] = k
        w.exp_negative[:inner_end] |= inner & (c[:inner_end] == 45)
        w.count[:inner_end] += inner


def _finish(w: _Walk, length, first):
    """(values, inexact) from the walk, or None if a token is malformed."""
    has_e = w.e > 0
    has_dot = w.dot > 0
    has_sign = (first == 45) | (first == 43)
    inner = w.inner_sign > 0
    exp_digits = w.e.astype(np.intp) - 1 - inner
    mant_digits = length - w.e - has_dot - has_sign
    bad = w.bad | (mant_digits < 1) | (w.count > has_dot.astype(np.uint8) + has_e + inner)
    bad |= has_e & (exp_digits < 1)
    bad |= inner & ~(has_e & (w.inner_sign + 1 == w.e))  # an inner sign must follow the 'e'
    bad |= ~has_e & inner
    if bad.any():
        return None
    # What lies right of a marker at byte position p is total mod 10**(p-1): the digits there
    # weigh less, those left of it are multiples of 10**p and the marker itself counts 0.
    e_digits = np.maximum(w.e.astype(np.intp) - 1, 0)
    at_e = np.where(has_e, _below(w.total, e_digits), 0.0)
    mant = (w.total - at_e) / _POW10[w.e]  # exact: the mantissa digits, re-based
    frac = np.where(has_dot, w.dot.astype(np.intp) - w.e - 1, 0)
    mant = _drop_marker(mant, frac, has_dot)
    power = np.where(w.exp_negative, -at_e, at_e) - frac
    inexact = (np.abs(power) > _MAX_POWER) | (w.total >= _EXACT)
    scale = _POW10[np.minimum(np.abs(power), _MAX_POWER).astype(np.intp)]
    values = np.where(power >= 0, mant * scale, mant / scale)
    values[first == 45] *= -1
    return values, inexact


def _unsort(found, order, b, starts, ends) -> np.ndarray:
    sorted_values, inexact = found
    # Well-formed but outside the exact range (huge mantissa or exponent): rare, use float().
    for i in np.flatnonzero(inexact):
        t = order[i]
        sorted_values[i] = float(b[starts[t]:ends[t]].tobytes())
    values = np.empty_like(sorted_values)
    values[order] = sorted_values
    return values
