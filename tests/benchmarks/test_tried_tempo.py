"""The tempo option tried and not shipped (``tried.Tried``) and the bench's slower and
quicker takes."""

import numpy as np
import pytest

from benchmarks.quality import variants
from benchmarks.quality.tried import (
    TEMPO_REFERENCE_S,
    TEMPO_SCALE,
    PacedAnalysis,
    Tried,
    movement_period,
    paced,
    scaled_times,
)
from motionlib import adapt, synth
from motionlib.errors import InputError, ParamError
from motionlib.segmenters.default import Default, take_features

FPS = 60.0


def _take(seed=2):
    return synth.generate(seed=seed, fps=FPS, n_segments=5, segment_seconds=(6, 8))


def test_a_take_played_slower_has_more_frames_and_its_cuts_move_with_the_motion():
    take, segments = _take()
    truth = np.asarray([start for start, _, _ in segments[1:]])
    slow, moved = variants.played_at(take, truth, 0.8)
    assert slow.n_frames == round(take.n_frames / 0.8)
    assert np.array_equal(moved, np.round(truth / 0.8).astype(np.int64))
    # The same pose at the moved frame as at the original one.
    assert np.allclose(slow.channels[moved[0]], take.channels[truth[0]], atol=2.0)


def test_an_angle_crossing_half_a_turn_is_resampled_through_its_shortest_turn():
    take, _ = _take()
    channels = np.array(take.channels, dtype=float)
    channels[:, 5] = np.where(np.arange(len(channels)) % 2 == 0, 179.0, -179.0)
    take.channels = channels
    slow, _ = variants.played_at(take, np.zeros(0, np.int64), 0.5)
    # Half-way between 179 and -179 is 180 (or -180), never 0.
    assert np.all(np.abs(np.abs(slow.channels[:, 5]) - 180.0) <= 1.0 + 1e-9)


def test_it_refuses_a_speed_that_is_not_above_zero():
    take, _ = _take()
    with pytest.raises(InputError, match="speed: must be above 0, got 0"):
        variants.played_at(take, np.zeros(0, np.int64), 0)


def test_the_movement_cycle_lengthens_as_the_performer_slows_down():
    take, _ = _take()
    periods = {}
    for speed in (0.8, 1.0, 1.25):
        played, _ = variants.played_at(take, np.zeros(0, np.int64), speed)
        x, _ = take_features(played)
        periods[speed] = movement_period(x, FPS)
    for speed in (0.8, 1.25):
        assert periods[speed] * speed == pytest.approx(periods[1.0], rel=0.1), periods


def test_a_take_too_short_or_without_repetition_has_no_cycle_and_keeps_its_settings():
    take, _ = _take()
    x, _ = take_features(take)
    assert movement_period(x[: int(3 * FPS)], FPS) is None  # shorter than the longest lag
    still = np.repeat(x[:1], int(20 * FPS), axis=0)
    assert movement_period(still, FPS) is None  # nothing moves away and comes back
    analysis = Tried.analyse(take.slice(0, int(3 * FPS)),
                             Tried.validate_params({"tempo": True}))
    assert analysis.tempo == 1.0


def test_tempo_scales_the_time_settings_by_the_takes_cycle_within_bounds():
    take, _ = _take()
    p = Tried.validate_params({"tempo": True})
    analysis = Tried.analyse(take, p)
    x, _ = take_features(take)
    expected = np.clip(movement_period(x, FPS) / TEMPO_REFERENCE_S, *TEMPO_SCALE)
    assert analysis.tempo == pytest.approx(expected)
    scaled = paced(analysis, p)
    for key in ("scale_min_s", "scale_max_s", "min_segment_s", "refine_s"):
        assert scaled[key] == pytest.approx(p[key] * analysis.tempo)
    assert scaled["threshold"] == p["threshold"]
    # Off, nothing is scaled.
    off = Tried.validate_params({})
    assert not isinstance(Tried.analyse(take, off), PacedAnalysis)
    assert paced(Tried.analyse(take, off), off) == off


def test_scaled_settings_stay_within_their_bounds():
    p = Default.validate_params({"scale_min_s": 15.0, "scale_max_s": 20.0, "rate_hz": 30.0})
    out = scaled_times(p, 2.0)
    assert out["scale_max_s"] <= 20.0 and out["rate_hz"] * out["scale_max_s"] <= 600
    assert out["scale_min_s"] <= out["scale_max_s"]


def test_with_tempo_it_cuts_as_the_windows_scaled_by_the_cycle_would():
    take, _ = _take()
    p = Tried.validate_params({"tempo": True})
    scale = Tried.analyse(take, p).tempo
    assert scale != 1.0
    with_tempo = Tried(tempo=True).fit_predict(take)
    by_hand = Default(**{k: v for k, v in scaled_times(p, scale).items() if k in Default.params})
    np.testing.assert_array_equal(with_tempo.cuts, by_hand.fit_predict(take).cuts)


def test_the_shipped_detector_and_adaptation_refuse_the_tempo_setting_by_name():
    take, segments = _take()
    truth = np.asarray([start for start, _, _ in segments[1:]])
    with pytest.raises(ParamError, match="tempo: unknown parameter for method 'default'"):
        Default(tempo=True).fit_predict(take)
    with pytest.raises(ParamError, match="tempo: unknown parameter for method 'default'"):
        adapt.fit_cut_model([(take, truth)], base={"tempo": True})
