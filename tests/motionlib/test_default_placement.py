"""Where the default detector puts a cut: at the onset of the next activity after a pause."""

import numpy as np
import pytest

from motionlib import synth
from motionlib.segmenters.default import Default
from motionlib.segmenters.default._placement import onset_frame

FPS = 60.0


def _take_with_pause(seed):
    """Two 8 s activities; the performer holds still for 2 s and then sets off again."""
    take, segments = synth.generate(seed=seed, fps=FPS, n_segments=2, segment_seconds=(8, 8))
    boundary, half = segments[1][0], int(FPS)
    frames = np.arange(take.n_frames)[:, None]
    ease = int(0.3 * FPS)  # slowing down and setting off take 0.3 s
    weight = np.maximum(np.clip((frames - (boundary + half)) / ease, 0, 1),
                        np.clip(((boundary - half) - frames) / ease, 0, 1))
    hold = take.channels[boundary - half]
    take.channels = hold * (1 - weight) + take.channels * weight
    return take, boundary + half


@pytest.mark.parametrize("seed", [0, 5])
def test_it_cuts_where_the_next_activity_sets_off_after_a_pause(seed):
    take, onset = _take_with_pause(seed)
    cuts = Default().fit_predict(take).cuts
    assert len(cuts) == 1 and abs(cuts[0] - onset) <= 0.1 * FPS


def test_it_cuts_inside_the_pause_without_the_onset_step():
    take, onset = _take_with_pause(0)
    cuts = Default(onset=False).fit_predict(take).cuts
    assert len(cuts) == 1 and onset - cuts[0] > 0.3 * FPS


def test_it_leaves_a_cut_before_a_slow_activity_in_place():
    # Fast, then a pause, then only a slow sway: the sway is an activity, not an onset.
    speed = np.concatenate([np.full(300, 10.0), np.full(60, 0.5), np.full(300, 2.0)])
    assert onset_frame(speed, 320, 480, 180) == 320


def test_it_moves_a_cut_in_a_short_pause_to_its_end():
    speed = np.concatenate([np.full(300, 10.0), np.full(60, 0.5), np.full(300, 10.0)])
    assert onset_frame(speed, 320, 480, 180) == 360


def test_it_leaves_a_cut_in_a_long_still_stretch_in_place():
    speed = np.concatenate([np.full(300, 10.0), np.full(400, 0.5), np.full(300, 10.0)])
    assert onset_frame(speed, 600, 780, 180) == 600
