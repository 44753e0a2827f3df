import math

import numpy as np
import pytest

from motionlib import metrics


def test_it_scores_a_hand_computed_case():
    # 205 is 5 frames from 200; nothing lies within 50 frames of 300; 100 and 400 are false.
    s = metrics.boundary_scores([100, 205, 400], [200, 300], fps=100, tolerance_s=0.5)
    assert s["matched"] == 1
    assert s["precision"] == pytest.approx(1 / 3)
    assert s["recall"] == pytest.approx(1 / 2)
    assert s["f1"] == pytest.approx(0.4)


def test_it_matches_each_true_cut_at_most_once():
    s = metrics.boundary_scores([100, 102], [101], fps=100, tolerance_s=0.5)
    assert (s["matched"], s["precision"], s["recall"]) == (1, 0.5, 1.0)


def test_it_finds_the_optimal_matching_where_nearest_first_would_not():
    # Nearest-first pairs 125 with 130 and leaves 150 and 100 unmatched; the optimal
    # matching pairs 125-100 and 150-130.
    ci, ti = metrics.match([125, 150], [100, 130], tolerance=25)
    assert sorted(zip(ci.tolist(), ti.tolist(), strict=True)) == [(0, 0), (1, 1)]


def test_it_prefers_the_closer_candidate_among_equal_sized_matchings():
    ci, ti = metrics.match([90, 104], [100], tolerance=20)
    assert (ci.tolist(), ti.tolist()) == ([1], [0])


def test_it_accepts_a_cut_anywhere_in_a_transition_window():
    truth = [[500, 550, 600]]
    assert metrics.boundary_scores([600], truth, fps=100, tolerance_s=0)["recall"] == 1
    assert metrics.boundary_scores([606], truth, fps=100, tolerance_s=0.05)["recall"] == 0


def test_it_repairs_a_window_given_out_of_order():
    assert metrics.as_windows([[3881, 3840, 4000]]).tolist() == [[3840, 3881, 4000]]


def test_it_rejects_truth_of_the_wrong_shape():
    with pytest.raises(ValueError, match=r"truth: expected .* got shape \(2, 2\)"):
        metrics.as_windows([[1, 2], [3, 4]])


def test_it_counts_deletes_inserts_and_moves():
    truth = [1000, 2000, 3000]
    cost = metrics.edit_cost([1010, 1080, 2500, 5000], truth, fps=100)
    assert (cost["deletes"], cost["inserts"], cost["moves"]) == (3, 2, 0)
    assert cost["edits_per_cut"] == pytest.approx(5 / 3)


def test_it_counts_a_move_for_a_matched_cut_more_than_a_quarter_second_off():
    assert metrics.edit_cost([1026], [1000], fps=100)["moves"] == 1
    assert metrics.edit_cost([1025], [1000], fps=100)["moves"] == 0


def test_it_needs_no_move_inside_a_wide_transition_window():
    assert metrics.edit_cost([590], [[500, 550, 600]], fps=100)["moves"] == 0
    assert metrics.edit_cost([590], [550], fps=100)["moves"] == 1


def test_it_reports_the_median_error_in_seconds():
    assert metrics.median_error_s([1010, 2030, 9000], [1000, 2000], fps=100) == pytest.approx(0.2)


def test_it_handles_no_candidates():
    s = metrics.boundary_scores([], [100], fps=100, tolerance_s=1)
    assert (s["precision"], s["recall"], s["f1"]) == (1.0, 0.0, 0.0)
    assert math.isnan(metrics.median_error_s([], [100], fps=100))
    assert metrics.edit_cost([], [100, 200], fps=100)["edits_per_cut"] == 1.0


def test_it_builds_the_benchmark_row():
    row = metrics.evaluate(np.array([1030, 2080]), [1000, 2000], fps=100)
    assert row["f1@0.5s"] == 0.5  # 2080 is 0.8 s from 2000
    assert row["f1@1s"] == 1.0
    assert row["edits_per_cut"] == 1.0  # both matched, both more than 0.25 s off
    assert row["median_error_s"] == pytest.approx(0.55)


def test_it_counts_matched_cuts_inside_their_transition_window():
    truth = [[500, 550, 600], [1000, 1050, 1100], [2000, 2000, 2000]]
    # 590 inside its window, 1150 matched but outside, 2010 has no window, 5000 unmatched.
    share = metrics.in_window_fraction([590, 1150, 2010, 5000], truth, fps=100)
    assert share == 0.5


def test_it_has_no_in_window_share_without_labelled_windows():
    assert math.isnan(metrics.in_window_fraction([1010], [1000], fps=100))
    assert math.isnan(metrics.in_window_fraction([], [[500, 550, 600]], fps=100))


def test_it_adds_the_in_window_share_to_the_benchmark_row():
    row = metrics.evaluate(np.array([590]), [[500, 550, 600]], fps=100)
    assert row["in_window"] == 1.0
    assert row["median_error_s"] == pytest.approx(0.4)  # still measured from the mid
