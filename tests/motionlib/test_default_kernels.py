"""The default detector's kernel arithmetic against its definitions, computed the slow
and obvious way: the MMD² novelty, the lag kernels it is built from, and the median
heuristic's squared distance."""

import numpy as np
import pytest

from motionlib.segmenters.default import _features, _novelty, _placement
from motionlib.segmenters.default._novelty import LAG_GROUP, LAG_ROWS, lag_kernel, multi_mmd_novelty


def _samples(n, d=5, seed=0):
    rng = np.random.default_rng(seed)
    # Two regimes, so the novelty has a peak and the kernel values spread over (0, 1].
    x = rng.normal(size=(n, d))
    x[n // 2 :] += 1.5
    return x


def _mmd2(past, future, gamma):
    def mean_kernel(a, b):
        d2 = ((a[:, None, :] - b[None, :, :]) ** 2).sum(axis=2)
        return np.exp(-gamma * d2).mean()

    return mean_kernel(past, past) + mean_kernel(future, future) - 2 * mean_kernel(past, future)


@pytest.mark.parametrize("n, widths", [
    (60, [1, 3, 7]),
    (LAG_ROWS + 37, [5, 20]),
    # more lags than one group: 2 w > LAG_GROUP
    (3 * LAG_ROWS + 5, [LAG_GROUP // 2 + 9, 11]),
])
def test_the_novelty_is_the_mmd2_of_the_windows_before_and_after_each_instant(n, widths):
    x, gamma = _samples(n), 0.3
    curves = multi_mmd_novelty(x, widths, gamma)
    for w, curve in zip(widths, curves, strict=True):
        expected = np.zeros(n)
        for t in range(w, n - w + 1):
            expected[t] = max(_mmd2(x[t - w : t], x[t : t + w], gamma), 0.0)
        np.testing.assert_allclose(curve, expected, rtol=1e-9, atol=1e-12)


def test_a_window_longer_than_half_the_take_gives_no_novelty():
    x = _samples(10)
    [curve] = multi_mmd_novelty(x, [6], 0.3)
    np.testing.assert_array_equal(curve, np.zeros(10))


@pytest.mark.parametrize("lags", [range(0, 7), range(5, 5 + LAG_GROUP), range(60, 75)])
def test_the_lag_kernel_is_the_kernel_between_each_sample_and_the_one_lag_later(lags):
    x, gamma = _samples(2 * LAG_ROWS + 9, d=4, seed=1), 0.7
    k = lag_kernel(x, lags, gamma)
    assert k.shape == (len(x), len(lags))
    for j, lag in enumerate(lags):
        expected = np.zeros(len(x))
        expected[: len(x) - lag] = np.exp(-gamma * ((x[lag:] - x[: len(x) - lag]) ** 2).sum(1))
        np.testing.assert_allclose(k[:, j], expected, rtol=1e-12, atol=1e-14)
    if lags[0] == 0:
        np.testing.assert_array_equal(k[:, 0], np.ones(len(x)))


def test_the_median_squared_distance_is_over_the_distinct_pairs_of_the_subsample():
    x = _samples(2500, d=3, seed=2)
    sub = x[::2]  # 2500 // 1000 = 2
    pairs = [((sub[i] - sub[j]) ** 2).sum() for i in range(len(sub)) for j in range(i + 1, len(sub))]
    assert _features.median_sq_distance(x) == pytest.approx(np.median(pairs), rel=1e-9)


def test_the_novelty_of_one_width_is_the_same_alone_or_with_others():
    x, gamma = _samples(400, seed=3), 0.4
    [alone] = multi_mmd_novelty(x, [40], gamma)
    together = multi_mmd_novelty(x, [12, 40, 70], gamma)[1]
    np.testing.assert_allclose(alone, together, rtol=1e-12, atol=1e-14)
    np.testing.assert_allclose(_novelty.mmd_novelty(x, 40, gamma), alone, rtol=1e-12,
                               atol=1e-14)


def test_the_split_gain_sums_the_kernel_inside_each_side_of_the_split():
    x, gamma = _samples(90, d=4, seed=4), 0.2
    k = np.exp(-gamma * ((x[:, None, :] - x[None, :, :]) ** 2).sum(axis=2))
    expected = [k[:t, :t].sum() / t + k[t:, t:].sum() / (90 - t) for t in range(1, 90)]
    gains = _placement.split_gains(x, gamma)
    np.testing.assert_allclose(gains, expected, rtol=1e-10)
    assert np.argmax(gains) + 1 == 45  # the regimes change half-way


def test_a_long_input_takes_its_lags_in_smaller_groups_with_the_same_novelty(monkeypatch):
    x, gamma = _samples(300, seed=5), 0.3
    whole = multi_mmd_novelty(x, [10, 25], gamma)
    monkeypatch.setattr(_novelty, "LAG_ELEMENTS", 300 * 7)  # 7 lags at a time
    grouped = multi_mmd_novelty(x, [10, 25], gamma)
    for a, b in zip(whole, grouped, strict=True):
        np.testing.assert_allclose(a, b, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("n, d", [(1, 3), (7, 2), (180, 31), (400, 62)])
def test_the_squared_distances_are_those_between_every_pair_of_rows(n, d):
    x = np.random.default_rng(n).normal(size=(n, d))
    expected = ((x[:, None, :] - x[None, :, :]) ** 2).sum(axis=2)
    d2 = _novelty.sq_distances(x)
    assert (d2 >= 0).all()
    np.testing.assert_allclose(d2, expected, rtol=1e-10, atol=1e-10)


def test_products_stay_small_enough_for_one_thread():
    assert _novelty._small_rows(180, 180, 31) * 180 * 31 <= _novelty.SMALL_PRODUCT
    assert _novelty._small_rows(10, 5, 3) == 10  # a small matrix in one product
    assert _novelty._small_rows(500, 100_000, 31) == 1  # never no rows at all
