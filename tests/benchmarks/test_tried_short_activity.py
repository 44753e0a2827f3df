"""The short-activity option tried and not shipped (``tried.Tried``, ``short_activity``):
the far side of an activity too short for the 3-6 s windows, confirmed by windows of
min_segment_s."""

import numpy as np
import pytest

from benchmarks.quality import tuning
from benchmarks.quality.tried import Tried, mixing
from motionlib import metrics, synth
from motionlib.segmenters.default import Analysis, Default
from tests.motionlib.conftest import skeleton_takes

FPS = 60.0
# A 1.8 s activity between two of 6 s: the 3-6 s windows see one broad peak.
SHORT_BETWEEN_LONG = [
    (1, ("idle", "kick", "walk")),
    (2, ("punch", "idle", "kick")),
    (9, ("arm_circles", "kick", "punch")),
]


def _short_between_long(seed, actions):
    before, short, after = actions
    take, segments = synth.generate(seed=seed, fps=FPS,
                                    plan=[(before, 6.0), (short, 1.8), (after, 6.0)])
    return take, np.asarray([start for start, _, _ in segments[1:]])


def _found(cuts, truth) -> int:
    _, ti = metrics.match(cuts, truth, tolerance=int(FPS))  # within 1 s
    return len(ti)


@pytest.mark.parametrize("seed, actions", SHORT_BETWEEN_LONG)
def test_it_cuts_both_sides_of_a_short_activity_between_two_long_ones(seed, actions):
    take, truth = _short_between_long(seed, actions)
    cuts = Tried(short_activity=4.0).fit_predict(take).cuts
    assert _found(cuts, truth) == 2
    assert len(cuts) == 2


@pytest.mark.parametrize("seed, actions", SHORT_BETWEEN_LONG)
def test_it_finds_one_side_only_with_the_long_windows_alone(seed, actions):
    # The limit the step addresses (the unmatched-poses step, on by default, is another
    # answer to it: test_default_unmatched).
    take, truth = _short_between_long(seed, actions)
    assert _found(Default(short_unmatched=0.0).fit_predict(take).cuts, truth) == 1


def test_it_ships_off_and_is_scored_as_a_tried_option():
    assert "short_activity" not in Default.params
    assert Tried.params["short_activity"].default == 0.0
    assert tuning.tried_grid()["short_activity"] == (0.0, *tuning.TRIED["short_activity"])


@pytest.mark.parametrize("seed", [0, 1])
def test_with_every_option_off_it_cuts_exactly_as_the_shipped_detector(seed):
    take, _ = synth.generate(seed=seed, fps=FPS, duration=40.0, segment_seconds=(1.5, 6.0))
    tried, shipped = Tried().fit_predict(take), Default().fit_predict(take)
    np.testing.assert_array_equal(tried.cuts, shipped.cuts)
    np.testing.assert_array_equal(tried.confidence, shipped.confidence)


@pytest.mark.parametrize("seed", [3, 4, 5])
def test_it_adds_no_cut_where_every_activity_is_long(seed):
    take, _ = synth.generate(seed=seed, fps=FPS, duration=40.0, segment_seconds=(4.0, 8.0))
    np.testing.assert_array_equal(Tried(short_activity=4.0).fit_predict(take).cuts,
                                  Default().fit_predict(take).cuts)


def test_it_rates_an_added_cut_as_the_weakest_peak_kept_on_its_own():
    take, _ = _short_between_long(*SHORT_BETWEEN_LONG[0])
    result = Tried(short_activity=4.0, short_unmatched=0.0).fit_predict(take)
    added = ~np.isin(result.cuts, Default(short_unmatched=0.0).fit_predict(take).cuts)
    assert added.sum() == 1
    assert result.confidence[added] == pytest.approx([0.5])  # prominence at the setting


@pytest.mark.slow
def test_it_adds_no_cut_to_the_real_full_skeleton_takes():
    for _, take in skeleton_takes():
        np.testing.assert_array_equal(Tried(short_activity=4.0).fit_predict(take).cuts,
                                      Default().fit_predict(take).cuts)


def _stream(*parts):
    """A 1-D pose stream at 10 Hz: (mean, samples) parts with a little noise."""
    rng = np.random.default_rng(0)
    x = np.concatenate([rng.normal(mean, 0.3, n) for mean, n in parts])[:, None]
    return Analysis(x=x, fps=10.0, step=1, first=0, gamma=1.0, novelty=np.zeros(len(x)),
                    timings={})


def test_it_sees_one_activity_as_uniform_and_a_passage_between_two_as_mixed():
    one = _stream((0, 20), (5, 20), (10, 20))
    passage = _stream((0, 20), (3, 10), (7, 10), (10, 20))
    assert mixing(one, 20, 40, 15) < 0.1
    assert mixing(passage, 20, 40, 15) > 1.0
    assert np.isnan(mixing(passage, 20, 22, 15))  # too short to halve


def test_it_keeps_a_uniform_short_activity_under_the_uniformity_test():
    take, truth = _short_between_long(*SHORT_BETWEEN_LONG[1])
    cuts = Tried(short_activity=4.0, short_uniformity=0.3).fit_predict(take).cuts
    assert _found(cuts, truth) == 2
