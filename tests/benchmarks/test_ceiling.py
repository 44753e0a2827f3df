"""The learning curve's oracle ceiling keeps the best subset of a take's candidates."""

import numpy as np
import pytest

from benchmarks.quality import ceiling
from motionlib import adapt

FPS = 10.0


def study(*frames_by_step):
    """A study whose candidates lie at ``frames_by_step`` (one list per placement step)."""
    stages = np.asarray(frames_by_step, dtype=np.int64).T
    n = len(stages)
    return {"stages": stages, "features": np.zeros((n, 9)), "zero_shot": np.zeros(n, bool),
            "fps": np.asarray(FPS), "n_frames": np.asarray(1000)}


def test_it_keeps_one_candidate_per_true_cut_the_nearest():
    one = study([100, 104, 300, 700])
    kept = ceiling.oracle_cuts(one, np.array([103, 305]), fps=FPS, tolerance_s=1.0)
    assert kept.tolist() == [104, 300]


def test_it_places_a_candidate_at_its_step_nearest_the_cut():
    one = study([100, 500], [120, 480])
    kept = ceiling.oracle_cuts(one, np.array([118, 485]), fps=FPS, tolerance_s=1.0)
    assert kept.tolist() == [120, 480]


def test_it_scores_a_cut_without_a_candidate_as_an_insert():
    one = study([100, 104, 700])
    recall, f1, edits = ceiling.take_ceiling(one, np.array([100, 400]), fps=FPS,
                                             tolerance_s=1.0)
    assert recall == 0.5 and f1 == pytest.approx(2 / 3) and edits == 0.5


def test_it_counts_a_window_and_its_tolerance_as_reachable():
    one = study([100, 150])
    windows = np.array([[120, 140, 160]])
    kept = ceiling.oracle_cuts(one, windows, fps=FPS, tolerance_s=1.0)
    assert kept.tolist() == [150]


def test_the_best_count_is_never_below_the_models_own_count():
    one = study(*[[100, 300, 500]] * 4)  # every placement step a model may cut at
    one["zero_shot"] = np.array([True, True, False])
    model = adapt.CutModel.zero_shot()
    truth = np.array([100, 300, 500])
    own = adapt.score_cuts(adapt.cuts_in(one, model), truth, fps=FPS)["f1"]
    assert ceiling.best_count(one, truth, model, fps=FPS, tolerance_s=1.0) >= own
    assert ceiling.best_count(one, truth, model, fps=FPS, tolerance_s=1.0) == 1.0
