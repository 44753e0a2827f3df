"""Vectorised parsing of whitespace-separated decimal numbers, line by line counts included.

``float()`` per token or ``np.loadtxt`` cost 40-100 ms for a 4,600-frame BVH; this parser works
on the raw bytes with a dozen numpy passes per chunk and gives bit-identical results for plain
decimals (``-17.2528``, ``0``, ``+3.``). Anything else (exponents, ``nan``, stray text, more than
about 15 digits) makes it return None so the caller can fall back to a careful line-by-line parse that
can also say what is wrong and where. Work is done in chunks of whole lines so the temporaries
stay small (peak memory about the size of the text plus the result) and in cache.
"""

from __future__ import annotations

import numpy as np

_POW10 = 10.0 ** np.arange(64)
_EXACT = 2.0**53  # integer sums below this are exact, so the one division rounds correctly
_MAX_TOKEN = 17
CHUNK_BYTES = 1 << 18


def parse_decimal_lines(data: bytes, offset: int = 0,
                        chunk_bytes: int = CHUNK_BYTES) -> tuple[np.ndarray, np.ndarray] | None:
    """Parse ``data[offset:]`` as lines of plain decimal numbers.

    Parameters
    ----------
    data : bytes
        ASCII text.
    offset : int
        Byte where the numbers start.

    Returns
    -------
    (values, per_line) or None
        ``values`` float64 of shape (n_tokens,) in reading order; ``per_line`` the number of
        tokens on each line (blank lines included, as 0). None when some token is not a plain
        decimal whose digits, read as an integer, stay below 2**53.
    """
    values, counts = [], []
    pos = offset
    while pos < len(data):
        end = data.find(b"\n", min(pos + chunk_bytes, len(data)) - 1)
        end = len(data) if end < 0 else end + 1
        parsed = _parse_chunk(np.frombuffer(data, dtype=np.uint8, count=end - pos, offset=pos))
        if parsed is None:
            return None
        values.append(parsed[0])
        counts.append(parsed[1])
        pos = end
    if not values:
        return np.zeros(0), np.zeros(0, np.intp)
    return np.concatenate(values), np.concatenate(counts)


def _parse_chunk(b: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """Values and tokens-per-line of one chunk of whole lines (see parse_decimal_lines)."""
    tok = (b > 32).view(np.int8)
    # Token edges: +1 where a token starts, -1 where one ends (padded so both always exist).
    edges = np.flatnonzero(np.diff(tok, prepend=np.int8(0), append=np.int8(0)))
    del tok
    starts, ends = edges[0::2].astype(np.int32), edges[1::2].astype(np.int32)
    del edges
    newlines = np.flatnonzero(b == 10)
    per_line = np.diff(np.searchsorted(starts, newlines), prepend=0, append=starts.size)
    values = _token_values(b, starts, ends)
    return None if values is None else (values, per_line)


def _token_values(b, starts, ends) -> np.ndarray | None:
    """Value of every token, walking all tokens from their last byte backwards in lockstep.

    Digits are summed with the weight of their byte position (10**(k-1) for the k-th byte from
    the right) so every pass multiplies by one scalar; the dot is corrected for afterwards:
    digits left of it were weighted ten times too much. Any byte that is not a digit, a dot or
    a leading sign rejects the chunk (None).
    """
    if starts.size == 0:
        return np.zeros(0)
    length = ends - starts
    longest = int(length.max())
    if longest > _MAX_TOKEN:
        return None
    length = length.astype(np.uint8)
    total = np.zeros(starts.size)
    right = np.zeros(starts.size)  # the sum when the dot is met: the fraction digits
    dot_at = np.zeros(starts.size, np.uint8)  # byte position of the dot from the right, 0 = none
    ndots = np.zeros(starts.size, np.uint8)
    bad = np.zeros(starts.size, bool)
    pos = ends.copy()
    for k in range(1, longest + 1):
        pos -= 1
        c = b[pos]  # bytes before a token's start (k > length) are masked by `valid`
        valid = length >= k
        d = c - np.uint8(48)
        isdig = d < 10
        isdot = c == 46
        sign = ((c == 45) | (c == 43)) & (length == k)
        bad |= valid & ~(isdig | isdot | sign)
        isdig &= valid
        d *= isdig
        total += d * _POW10[k - 1]
        isdot &= valid
        if isdot.any():
            np.copyto(right, total, where=isdot)
            dot_at[isdot] = k
            ndots += isdot
    first = b[starts]
    has_sign = (first == 45) | (first == 43)
    no_digit = length == ndots + has_sign
    if np.any(bad | no_digit | (ndots > 1)) or total.max() >= _EXACT:
        return None
    # Integer mantissa (exact below 2**53), then one correctly rounded division.
    frac = np.where(dot_at > 0, dot_at.astype(np.intp) - 1, 0)
    total -= right
    total /= np.where(dot_at > 0, 10.0, 1.0)
    total += right
    total /= _POW10[frac]
    total[first == 45] *= -1
    return total
