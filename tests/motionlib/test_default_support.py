"""The default detector's support test (``support``): a novelty peak whose poses on each
side all have look-alikes on the other side is inside one activity, not between two."""

import numpy as np
import pytest

from motionlib import metrics
from motionlib.segmenters.default import Analysis, Default, candidates, peak_support
from motionlib.segmenters.default._peaks import SUPPORT_GAP_S, SUPPORT_SIDE_S, cross_support
from tests.motionlib.conftest import labelled_takes, skeleton_takes

RATE = 10.0


def _circle(seconds: float, *, period: float = 1.0, centre=(0.0, 0.0)) -> np.ndarray:
    """A repeating activity at 10 Hz: a 2-D pose going round a unit circle."""
    t = np.arange(int(round(seconds * RATE))) / RATE
    return np.column_stack([np.cos(2 * np.pi * t / period) + centre[0],
                            np.sin(2 * np.pi * t / period) + centre[1]])


def _uneven(seconds: float, period: float = 2.0) -> np.ndarray:
    """The same circle at an uneven speed: slow through the top, quick through the
    bottom, so its poses come in other proportions."""
    t = np.arange(int(round(seconds * RATE))) / RATE
    angle = 2 * np.pi * t / period
    angle = angle - 0.6 * np.cos(angle)  # d(angle)/dt is smallest near angle pi/2
    return np.column_stack([np.cos(angle), np.sin(angle)])


def test_a_boundary_between_two_activities_is_supported():
    x = np.concatenate([_circle(10), _circle(10, centre=(3.0, 0.0))])
    score = cross_support(x, np.array([100]), RATE, gamma=1.0)
    # Every pose after the peak is a circle shifted by 3: its nearest pose before the
    # peak is at least 1 away (squared), most much further.
    assert score[0] > 1.0


def test_phases_of_one_activity_in_other_proportions_are_not():
    # The same movement, the second half dwelling on the top of the circle: the windows
    # see other proportions (a novelty peak), but every pose on either side of the peak
    # is taken on the other side too (to within the 10 Hz sampling of the circle).
    x = np.concatenate([_circle(10, period=2.0), _uneven(10)])
    score = cross_support(x, np.array([100]), RATE, gamma=1.0)
    assert score[0] < 0.03


def test_it_is_the_larger_side_that_counts():
    # Standing at a pose the circle passes through: every pose after the peak was seen
    # before it, but most poses before it are never seen after.
    still = np.tile([[1.0, 0.0]], (100, 1))
    x = np.concatenate([_circle(10), still])
    score = cross_support(x, np.array([100]), RATE, gamma=1.0)
    assert score[0] > 0.5


def test_the_passage_around_the_peak_is_left_out():
    # Poses that exist only within the gap around the peak do not count.
    gap = int(round(SUPPORT_GAP_S * RATE))
    x = _circle(20)
    x[100 - gap:101 + gap] += 10.0
    assert cross_support(x, np.array([100]), RATE, gamma=1.0)[0] < 1e-9


def test_a_peak_with_too_little_on_one_side_is_never_dropped():
    side = int(round(SUPPORT_SIDE_S * RATE))
    x = _circle(20)
    score = cross_support(x, np.array([1, 100, 198]), RATE, gamma=1.0)
    assert np.isinf(score[0]) and np.isinf(score[2]) and np.isfinite(score[1])
    assert side < 100


def test_the_score_is_in_kernel_units():
    x = np.concatenate([_circle(10), _circle(10, centre=(3.0, 0.0))])
    one = cross_support(x, np.array([100]), RATE, gamma=1.0)
    np.testing.assert_allclose(cross_support(x, np.array([100]), RATE, gamma=0.25), 0.25 * one)


def _analysis(x: np.ndarray, novelty: np.ndarray) -> Analysis:
    return Analysis(x=x, fps=RATE, step=1, first=0, gamma=1.0, novelty=novelty, timings={})


def _two_joins() -> Analysis:
    """Three stretches: a circle, the same circle at an uneven speed, another circle. The
    novelty (given) has a peak at both joins; only the second is a boundary."""
    x = np.concatenate([_circle(10, period=2.0), _uneven(10), _circle(10, centre=(3.0, 0.0))])
    novelty = np.zeros(len(x))
    novelty[95:106] = np.hanning(11)
    novelty[195:206] = np.hanning(11)
    return _analysis(x, novelty)


def test_window_peaks_drops_the_unsupported_peak_only():
    analysis = _two_joins()
    on = Default.validate_params({})
    off = Default.validate_params({"support": 0.0})
    assert Default.window_peaks(analysis, off)[0].tolist() == [100, 200]
    peaks, strength = Default.window_peaks(analysis, on)
    assert peaks.tolist() == [200]
    assert strength.tolist() == pytest.approx([1.0])


def test_no_prominence_brings_back_a_peak_the_support_test_drops():
    # ``candidates`` lists every peak any prominence would keep, but not one the support
    # test drops: a count chosen among them cannot cut there.
    analysis = _two_joins()
    on = Default.validate_params({})
    off = Default.validate_params({"support": 0.0})
    for p, kept in ((off, [100, 200]), (on, [200])):
        peaks, _ = candidates(analysis, Default.peaks(analysis, p), p)
        assert peaks.tolist() == kept


def test_the_support_the_learner_reads_is_the_support_test_s():
    analysis = _two_joins()
    expected = cross_support(analysis.blocks, np.array([100, 200]), analysis.rate,
                             analysis.gamma)
    np.testing.assert_array_equal(peak_support(analysis, [100, 200]), expected)
    assert Default.peaks(analysis, Default.validate_params({})).samples.tolist() == [200]


def test_the_four_channel_cuts_it_drops_are_far_from_every_true_cut():
    # 86_02 and 86_10 (subject 86, four angle channels): the cuts the test removes lie
    # inside exercises, and no true cut is lost.
    for name in ("86_02", "86_10"):
        labelled = labelled_takes("channels", name)[0]
        take = labelled.read()
        on = Default().fit_predict(take).cuts
        off = Default(support=0.0).fit_predict(take).cuts
        # The cuts of ``off`` with none of ``on`` within 1 s (a neighbour dropped can
        # move a cut: its placement never reaches past half-way to the next cut).
        one_s = int(round(take.fps))
        dropped = off[np.abs(off[:, None] - on[None, :]).min(axis=1) > one_s]
        assert len(dropped) >= 1, name
        assert len(on) == len(off) - len(dropped), name
        mids = metrics.as_windows(labelled.truth)[:, 1]
        assert np.abs(dropped[:, None] - mids[None, :]).min() > 1.5 * take.fps, name
        assert len(metrics.match(on, labelled.truth, tolerance=one_s)[0]) == \
            len(metrics.match(off, labelled.truth, tolerance=one_s)[0]), name


def test_the_full_skeleton_takes_keep_their_cuts():
    for labelled, take in skeleton_takes():
        on = Default().fit_predict(take).cuts
        off = Default(support=0.0).fit_predict(take).cuts
        assert on.tolist() == off.tolist(), labelled.name


def test_a_short_activity_between_two_alike_ones_is_kept():
    # 10 s of circles, 1.2 s held far away, 10 s of circles: the held poses straddle the
    # peak, so each side holds them and the circles, and every pose is matched across
    # (the support test alone would drop the peak); the unmatched-poses step reads the
    # stretch as a short activity, and the peak stays to be split into its two sides.
    still = np.tile([[4.0, 0.0]], (12, 1))
    x = np.concatenate([_circle(10), still, _circle(10)])
    novelty = np.zeros(len(x))
    novelty[100:113] = np.hanning(13)
    analysis = _analysis(x, novelty)
    assert cross_support(x, np.array([106]), RATE, gamma=1.0)[0] < 0.5
    on = Default.validate_params({})
    assert Default.window_peaks(analysis, on)[0].tolist() == [106]
    assert len(Default.peaks(analysis, on).samples) == 2
    without = Default.validate_params({"short_unmatched": 0.0})
    assert Default.window_peaks(analysis, without)[0].tolist() == []
