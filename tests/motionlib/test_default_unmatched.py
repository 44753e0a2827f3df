"""The default detector's unmatched-poses step (``short_unmatched``, step 4c): both sides
of an activity too short for the 3-6 s windows, found where the poses near a kept peak
look like nothing 1.5-8 s around them."""

import numpy as np
import pytest

from benchmarks.quality import data, tuning, variants
from motionlib import metrics
from motionlib.segmenters.default import Analysis, Default
from motionlib.segmenters.default._unmatched import (
    UNMATCHED_HALF_S,
    UNMATCHED_RELATIVE,
    unmatched_peaks,
    unmatched_poses,
    unmatched_sides,
)
from tests.motionlib.conftest import labelled_takes, skeleton_takes

RATE = 10.0


def _cycles(seconds: float, phase: float = 0.0) -> np.ndarray:
    """A repeating activity at 10 Hz: a 2-D pose going round a circle once a second."""
    t = np.arange(int(round(seconds * RATE))) / RATE
    return np.column_stack([np.cos(2 * np.pi * t + phase), np.sin(2 * np.pi * t + phase)])


def _still(seconds: float, at) -> np.ndarray:
    return np.tile(np.asarray(at, dtype=float), (int(round(seconds * RATE)), 1))


def _analysis(x: np.ndarray) -> Analysis:
    return Analysis(x=x, fps=RATE, step=1, first=0, gamma=1.0, novelty=np.zeros(len(x)),
                    timings={})


def test_a_repeating_activity_matches_itself_and_a_short_different_one_does_not():
    # 10 s of cycles, 2 s held far away, 10 s of cycles again.
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    score = unmatched_poses(x, RATE, gamma=1.0, nearest_s=1.5)
    inside = np.r_[20:80, 140:200]
    assert score[inside].max() < 1e-9  # a cycle later the same poses come round again
    # The middle of the held stretch has only the cycles in reach: squared distance
    # from (4, 0) to the unit circle's nearest point is 9.
    np.testing.assert_allclose(score[105:115], 9.0, rtol=1e-9)


def test_nothing_in_reach_scores_zero_not_infinity():
    assert unmatched_poses(_cycles(1.0), RATE, gamma=1.0, nearest_s=1.5).tolist() == [0.0] * 10


def test_the_score_is_in_kernel_units():
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10)])
    one = unmatched_poses(x, RATE, gamma=1.0, nearest_s=1.5)
    np.testing.assert_allclose(unmatched_poses(x, RATE, gamma=0.25, nearest_s=1.5), 0.25 * one)


def _peaks(x: np.ndarray, peaks, level: float = 1.0):
    p = Default.validate_params({"short_unmatched": level})
    out, evidence = unmatched_peaks(_analysis(x), np.asarray(peaks, dtype=np.int64),
                                    np.asarray([0.3] * len(peaks)), p)
    return out.tolist(), evidence.tolist()


def test_a_peak_beside_a_short_unmatched_stretch_becomes_its_two_sides():
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    # The long windows put one peak inside the held stretch (frames 100-119).
    peaks, evidence = _peaks(x, [104])
    half = UNMATCHED_HALF_S * RATE
    # Each side its half-width from the stretch's middle (110), to within 1.5 blocks.
    assert abs(peaks[0] - (110 - half)) <= 1.5 and abs(peaks[1] - (110 + half)) <= 1.5
    assert evidence == [0.3, 0.3]  # both sides keep the evidence of the peak they replace


def test_a_matched_stretch_or_the_step_off_leaves_the_peak():
    x = np.concatenate([_cycles(10), _cycles(10, phase=1.0)])
    assert _peaks(x, [100]) == ([100], [0.3])
    held = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    assert _peaks(held, [104], level=100.0) == ([104], [0.3])  # below the level


def test_a_side_too_near_the_end_of_the_take_keeps_the_peak():
    # The held stretch at the very start: its first side would lie before the take's
    # first min_segment_s / 2, where no cut may go.
    x = np.concatenate([_still(1.2, (4.0, 0.0)), _cycles(12)])
    assert _peaks(x, [10]) == ([10], [0.3])


def test_of_two_cuts_closer_than_the_minimum_segment_the_earlier_stays():
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    # A kept peak at 86 reaches only the edge of the held stretch (below the level, so
    # it stays); the first side of the peak at 104 would lie 1.3 s after it.
    alone, _ = _peaks(x, [104], level=5.0)
    assert alone[0] - 86 < 15  # min_segment_s: 15 blocks
    assert _peaks(x, [86, 104], level=5.0)[0] == [86, alone[1]]


def test_a_stretch_with_kept_peaks_on_both_sides_keeps_them():
    # The long windows found both sides of the held stretch (within scale_min_s of its
    # middle): nothing to add, nothing to move.
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    assert _peaks(x, [98, 121]) == ([98, 121], [0.3, 0.3])


def test_in_a_take_that_never_repeats_itself_an_unmatched_stretch_says_nothing():
    # Poses drifting along a line at 1 unit a second: nothing 1.5 s away or more looks
    # alike anywhere (2.25 everywhere, above the level 1), so the stretch near the peak
    # is no more unmatched than the rest of the take.
    x = np.column_stack([np.arange(200) / RATE, np.zeros(200)])
    assert _peaks(x, [104]) == ([104], [0.3])
    # The absolute level alone would split the peak.
    p = Default.validate_params({"short_unmatched": 1.0})
    out, _ = unmatched_peaks(_analysis(x), np.asarray([104]), np.asarray([0.3]), p,
                             relative=0.0)
    assert len(out) == 2


def test_a_short_activity_stands_out_of_a_take_that_repeats_itself_by_far_more():
    # The held stretch among cycles: its level (9) against a take median near 0.
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    score = unmatched_poses(x, RATE, gamma=1.0, nearest_s=1.5)
    assert 9.0 > 10 * UNMATCHED_RELATIVE * np.median(score)
    assert len(_peaks(x, [104])[0]) == 2


def test_it_ships_on_and_is_chosen_from_the_grid():
    assert Default.params["short_unmatched"].default == 1.0
    assert tuning.GRID["short_unmatched"] == (0.0, 1.0)


# Real short activities: an inner activity of a real take cut down by removing its middle
# (its entry and exit as the performer made them); (take, activity) pairs where the
# step finds both sides at 1.8 s.
REAL_CASES = [("13_30", 1), ("86_01", 2)]


def _sides_found(cuts, truth, k, fps) -> int:
    _, ti = metrics.match(cuts, truth, tolerance=int(round(fps)))  # within 1 s
    return int(k in ti) + int(k + 1 in ti)


@pytest.mark.slow
@pytest.mark.parametrize("name, activity", REAL_CASES)
def test_it_finds_both_sides_of_a_real_activity_cut_down_to_1_8_s(name, activity):
    labelled = labelled_takes(name=name)[0]
    take, truth = variants.shortened(labelled.read(), labelled.truth, activity, 1.8)
    cuts = Default().fit_predict(take).cuts
    assert _sides_found(cuts, truth, activity, take.fps) == 2
    # Without the step, the long windows see one peak and one side is lost.
    assert _sides_found(Default(short_unmatched=0.0).fit_predict(take).cuts, truth,
                        activity, take.fps) == 1


@pytest.mark.slow
def test_it_finds_the_real_1_6_s_activity_of_a_four_channel_take():
    # 86_14's "through_ball" between two "walk_lead_ball" stretches lasts 1.6 s.
    labelled = labelled_takes("channels", "86_14")[0]
    take = labelled.read()
    truth = labelled.truth
    short = int(np.argmin(np.diff(truth[:, 1])))
    assert np.diff(truth[:, 1])[short] / take.fps < 1.7
    assert _sides_found(Default().fit_predict(take).cuts, truth, short, take.fps) == 2
    assert _sides_found(Default(short_unmatched=0.0).fit_predict(take).cuts, truth, short,
                        take.fps) == 1


@pytest.mark.slow
def test_it_adds_no_cut_to_the_real_full_skeleton_takes_as_they_are():
    for _, take in skeleton_takes():
        np.testing.assert_array_equal(Default().fit_predict(take).cuts,
                                      Default(short_unmatched=0.0).fit_predict(take).cuts)


@pytest.mark.slow
def test_the_take_median_guard_keeps_it_out_of_a_boxing_take():
    # CMU 13_17, boxing throughout (no segment labels): punches and footwork that never
    # repeat exactly, so the median pose is already 0.62 unmatched; the stretch the
    # absolute level (1) alone would split sits at 1.7 times the take's median.
    found = [(path, asf) for path, asf in data.unlabelled_motion()
             if path.stem == "13_17"]
    if not found:
        pytest.skip("CMU take 13_17 is not available (needs ../shared/data)")
    import motionlib

    take = motionlib.read(found[0][0], asf=found[0][1])
    p = Default.validate_params({})
    analysis = Default.analyse(take, p)
    peaks, _ = Default.window_peaks(analysis, p)
    assert unmatched_sides(analysis, peaks, p, relative=0.0)  # the level alone fires
    assert unmatched_sides(analysis, peaks, p) == {}
    np.testing.assert_array_equal(Default().fit_predict(take).cuts,
                                  Default(short_unmatched=0.0).fit_predict(take).cuts)


def test_a_subclass_sets_the_half_width_and_the_guard_of_the_step():
    x = np.concatenate([_cycles(10), _still(2, (4.0, 0.0)), _cycles(10, phase=1.0)])
    analysis, p = _analysis(x), Default.validate_params({})
    novelty = np.zeros(len(x))
    novelty[99:110] = np.hanning(11)  # one broad peak inside the held stretch, at 104
    analysis.novelty = novelty
    shipped = Default.peaks(analysis, p)
    wider = type("Wider", (Default,), {"unmatched_half_s": UNMATCHED_HALF_S + 0.5})
    found = wider.peaks(analysis, p)
    assert shipped.sides.keys() == found.sides.keys() == {104}
    middle, half = np.mean(shipped.sides[104]), (UNMATCHED_HALF_S + 0.5) * RATE
    np.testing.assert_allclose(found.sides[104], [middle - half, middle + half], atol=1)
    assert found.samples.tolist() == list(found.sides[104])
    # The evidence of the step: the stretch's level over the take's median, far above the
    # guard, which a subclass can also lower (here to nothing but the level itself).
    assert shipped.unmatched[104] > 10 * UNMATCHED_RELATIVE
    guardless = type("Guardless", (Default,), {"unmatched_relative": 0.0})
    line = Analysis(x=np.column_stack([np.arange(200) / RATE, np.zeros(200)]), fps=RATE,
                    step=1, first=0, gamma=1.0, novelty=novelty[:200], timings={})
    assert Default.peaks(line, p).sides == {}
    assert guardless.peaks(line, p).sides.keys() == {104}
