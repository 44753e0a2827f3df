"""Segmenters use a take's precomputed world positions (``Take.positions``) when set, with
the same result as computing them, and never write into them."""

import numpy as np
import pytest

import motionlib
from motionlib import synth
from motionlib.segmenters import get_segmenter, list_segmenters


@pytest.fixture(scope="module")
def take():
    generated, _ = synth.generate(seed=11, fps=120.0, duration=40.0)
    return generated


@pytest.mark.parametrize("name", [cls.name for cls in list_segmenters()])
def test_it_finds_the_same_cuts_from_given_read_only_positions(take, name):
    computed = get_segmenter(name)().fit_predict(take)
    given = motionlib.Take(**{**take.__dict__, "positions": motionlib.forward_kinematics(take)})
    given.positions.flags.writeable = False
    reused = get_segmenter(name)().fit_predict(given)
    np.testing.assert_array_equal(reused.cuts, computed.cuts)
    np.testing.assert_array_equal(reused.confidence, computed.confidence)


def test_it_does_not_compute_positions_it_was_given(take, monkeypatch):
    given = motionlib.Take(**{**take.__dict__, "positions": motionlib.forward_kinematics(take)})
    calls = []
    real = motionlib.forward_kinematics
    monkeypatch.setattr(motionlib, "forward_kinematics", lambda *a, **k: calls.append(1) or real(*a, **k))
    get_segmenter("default")().fit_predict(given)
    assert calls == []


def test_a_slice_keeps_the_positions_of_its_frames(take):
    given = motionlib.Take(**{**take.__dict__, "positions": motionlib.forward_kinematics(take)})
    part = given.slice(100, 700)
    np.testing.assert_array_equal(part.positions, motionlib.forward_kinematics(part))


@pytest.mark.parametrize("velocity_s", [0.0, 0.3])
def test_the_default_detectors_features_from_the_channels_equal_those_from_positions(
    take, velocity_s
):
    """Without positions the default detector computes its features straight from the
    channels (``kinematics.body_frame_rows``): the same values to the last bit."""
    from motionlib.segmenters.default import take_features

    given = motionlib.Take(**{**take.__dict__, "positions": motionlib.forward_kinematics(take)})
    from_channels, first = take_features(take, velocity_s=velocity_s)
    from_positions, first_given = take_features(given, velocity_s=velocity_s)
    assert first == first_given == 0
    np.testing.assert_array_equal(from_channels, from_positions)
