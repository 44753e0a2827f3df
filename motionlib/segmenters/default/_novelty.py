"""Stage 2 of the default detector: kernel novelty of the pose stream.

At each instant the poses of the past and the future window are compared with the
maximum mean discrepancy (MMD²) under a Gaussian kernel: 0 for identical distributions,
near 2 for disjoint ones, whatever the capture's units. The kernel sums are computed lag
by lag in small matrix products, so memory and time grow with n x window, not n².
"""

from __future__ import annotations

import numpy as np


def mmd_novelty(x: np.ndarray, w: int, gamma: float) -> np.ndarray:
    """MMD² between the ``w`` samples before and the ``w`` samples from each instant.

    Only kernel values at lags below ``2 w`` are needed, so memory and time are
    O(n w) rather than O(n²), which keeps hour-long takes cheap.

    Parameters
    ----------
    x : (n, d) samples; w : window length in samples; gamma : kernel 1 / bandwidth².

    Returns
    -------
    (n,) biased MMD² estimate at each split t (0 where a window would leave the take).
    """
    return multi_mmd_novelty(x, [w], gamma)[0]


def multi_mmd_novelty(x: np.ndarray, widths, gamma: float) -> list[np.ndarray]:
    """``mmd_novelty`` for several window lengths, sharing the kernel at each lag.

    Returns
    -------
    list of (n,) arrays, one per width in ``widths``.
    """
    n = len(x)
    acc = {}
    for w in widths:
        if w >= 1 and n >= 2 * w:
            t = np.arange(w, n - w + 1)
            acc[w] = (t, np.zeros(len(t)), np.zeros(len(t)))
    n_lags = 2 * max(acc, default=0)
    group = max(1, min(LAG_GROUP, LAG_ELEMENTS // max(n, 1)))
    for first in range(0, n_lags, group):
        lags = range(first, min(n_lags, first + group))
        # sums[i, j]: the kernel at lag lags[j] summed over the pairs starting before i
        sums = np.zeros((n + 1, len(lags)))
        np.cumsum(lag_kernel(x, lags, gamma), axis=0, out=sums[1:])
        for lag, c in zip(lags, sums.T, strict=True):
            _add_lag(acc, lag, np.ascontiguousarray(c))
    out = []
    for w in widths:
        curve = np.zeros(n)
        if w in acc:
            t, within, cross = acc[w]
            curve[t] = np.maximum((within - 2 * cross) / (w * w), 0.0)
        out.append(curve)
    return out


# Lags whose kernels are computed together: LAG_GROUP, fewer on long inputs so that each
# of the few (n, lags) arrays holds at most LAG_ELEMENTS values (8 MB: an hour-long take
# needs no more memory than a short one); and the most rows per matrix product (each
# row's product also covers lags - 1 columns it does not need, so short blocks waste
# less), fewer when the product would exceed SMALL_PRODUCT.
LAG_GROUP = 64
LAG_ELEMENTS = 2**20
LAG_ROWS = 64
# Matrix products of m x n x k at most this size: OpenBLAS computes them on one thread and
# splits larger ones over threads, which is slower when the other cores are busy.
SMALL_PRODUCT = 4 * 65536


def _small_rows(rows: int, cols: int, d: int) -> int:
    """At most ``rows``, and few enough that rows x cols x d stays within SMALL_PRODUCT."""
    return max(1, min(rows, SMALL_PRODUCT // max(1, cols * d)))


def lag_kernel(x: np.ndarray, lags: range, gamma: float) -> np.ndarray:
    """The Gaussian kernel between each sample and the one ``lag`` later, for each lag.

    ``|a - b|² = |a|² + |b|² - 2 a.b`` with the dot products from matrix products over
    short blocks of rows: the products of a band of the Gram matrix, several times fewer
    passes over memory than differencing the samples lag by lag.

    Returns
    -------
    (n, len(lags)): ``exp(-gamma |x[i + lag] - x[i]|²)``, 0 where ``i + lag`` is past the
    end; exactly 1 at lag 0.
    """
    n, m, first = len(x), len(lags), lags[0]
    sq = np.einsum("ij,ij->i", x, x)
    dots = np.empty((n, m))
    rows = LAG_ROWS
    while rows > 1 and rows * (rows + m - 1) * x.shape[1] > SMALL_PRODUCT:
        rows //= 2
    for a in range(0, n, rows):
        b = min(n, a + rows)
        block = np.zeros((b - a, b - a + m - 1))
        later = x[a + first : b + first + m - 1]
        block[:, : len(later)] = x[a:b] @ later.T
        # row r of the band starts at block[r, r]: one step further along each row
        dots[a:b] = np.lib.stride_tricks.as_strided(
            block, shape=(b - a, m), strides=(block.strides[0] + block.strides[1],
                                              block.strides[1]))
    padded = np.concatenate([sq, np.zeros(first + m)])
    sq_later = np.lib.stride_tricks.sliding_window_view(padded[first:], m)[:n]
    k = np.exp(-gamma * np.maximum(sq[:, None] + sq_later - 2 * dots, 0.0))
    for j, lag in enumerate(lags):
        k[max(0, n - lag):, j] = 0.0
    if first == 0:
        k[:, 0] = 1.0
    return k


def _add_lag(acc: dict, lag: int, c: np.ndarray) -> None:
    """Add the pairs at ``lag`` to each width's within- and cross-window kernel sums;
    ``c[i]`` sums their kernel over the pairs starting before ``i``."""
    for w, (t, within, cross) in acc.items():
        if lag >= 2 * w:
            continue

        def at(offset, w=w, t=t):  # c[t + offset] for every split t (a slice, not a gather)
            return c[t[0] + offset : t[0] + offset + len(t)]

        if lag < w:  # pairs (i, i + lag) inside the past and inside the future window
            mult = 1.0 if lag == 0 else 2.0
            within += mult * (at(-lag) - at(-w) + at(w - lag) - at(0))
        # pairs with i in the past window and i + lag in the future one: i from
        # max(t - w, t - lag) up to min(t, t + w - lag)
        if 1 <= lag <= w:
            cross += at(0) - at(-lag)
        elif lag > w:
            cross += at(w - lag) - at(-w)


def mirrored_novelty(x: np.ndarray, w: int, gamma: float) -> np.ndarray:
    """``mmd_novelty`` with the take mirrored at both ends.

    Mirroring lets a window that would run off the take see the nearest real poses
    again, so an activity shorter than a window at the very start or end still
    produces a peak at its boundary.
    """
    return mirrored_novelties(x, [w], gamma)[0]


def mirrored_novelties(x: np.ndarray, widths, gamma: float) -> list[np.ndarray]:
    """``mirrored_novelty`` for several widths at once (one mirror, shared kernels)."""
    widths = [min(w, len(x) - 1) for w in widths]
    pad = max(widths, default=0)
    if pad < 1:
        return [np.zeros(len(x)) for _ in widths]
    padded = np.concatenate([x[pad:0:-1], x, x[-2 : -pad - 2 : -1]])
    curves = multi_mmd_novelty(padded, widths, gamma)
    return [c[pad : pad + len(x)] if w >= 1 else np.zeros(len(x))
            for c, w in zip(curves, widths, strict=True)]


def sq_distances(x: np.ndarray) -> np.ndarray:
    """(n, n) squared distances between the rows of ``x``: ``|a|² + |b|² - 2 a.b`` (at
    least 0) with the dot products from matrix products of a few rows each, small enough
    (SMALL_PRODUCT) to run on one thread, which is quicker than ``cdist``."""
    n, d = x.shape
    sq = np.einsum("ij,ij->i", x, x)
    gram = np.empty((n, n))
    rows = _small_rows(n, n, d)
    for a in range(0, n, rows):
        gram[a : a + rows] = x[a : a + rows] @ x.T
    return np.maximum(sq[:, None] + sq[None, :] - 2 * gram, 0.0)


def window_widths(scale_min_s: float, scale_max_s: float, rate: float) -> list[int]:
    """Three window lengths evenly spread between the two scales, in samples at ``rate``."""
    scales = np.linspace(scale_min_s, scale_max_s, 3)
    return sorted({max(1, int(round(s * rate))) for s in scales})
