"""Agreement between annotators, checked against cases worked out by hand and against
published values."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionlib.agreement import (
    boundary_agreement,
    cohen_kappa,
    krippendorff_alpha,
    label_codes,
    label_overlap,
    segment_support,
    take_agreement,
)


def test_it_matches_cuts_within_the_tolerance_one_to_one():
    # fps 100, 0.25 s = 25 frames: 100~110 match; 200 and 300 are 60 and 40 from 260.
    scores = boundary_agreement([100, 200, 300], [110, 260], fps=100, tolerance_s=0.25)
    assert scores["matched"] == 1
    assert_allclose([scores["precision"], scores["recall"], scores["f1"]], [1 / 3, 1 / 2, 2 / 5])


def test_it_is_symmetric_in_f1():
    a, b = [10, 50, 90, 130], [12, 88, 200]
    f_ab = boundary_agreement(a, b, fps=30, tolerance_s=0.25)["f1"]
    f_ba = boundary_agreement(b, a, fps=30, tolerance_s=0.25)["f1"]
    assert f_ab == f_ba == pytest.approx(2 * 2 / 7)


def test_it_does_not_let_one_cut_match_two():
    scores = boundary_agreement([100], [95, 105], fps=100, tolerance_s=0.25)
    assert scores["matched"] == 1
    assert scores["recall"] == 0.5


def test_it_counts_two_annotators_without_cuts_as_agreeing():
    assert boundary_agreement([], [], fps=120)["f1"] == 1.0
    assert boundary_agreement([], [40], fps=120)["f1"] == 0.0


def test_it_rejects_a_negative_tolerance_naming_it():
    with pytest.raises(ValueError, match="tolerance_s: must be >= 0, got -1"):
        boundary_agreement([1], [1], fps=120, tolerance_s=-1)


def test_it_computes_cohen_kappa_of_a_hand_worked_case():
    # Agree on 7 of 10 frames; A: 4 x 0, 6 x 1; B: 5 x 0, 5 x 1.
    # p_o = 0.7, p_e = (4*5 + 6*5) / 100 = 0.5, kappa = 0.2 / 0.5 = 0.4.
    a = [0, 0, 0, 0, 1, 1, 1, 1, 1, 1]
    b = [0, 0, 0, 1, 1, 1, 1, 1, 0, 0]
    assert cohen_kappa(a, b) == pytest.approx(0.4)


def test_it_agrees_with_statsmodels_on_random_labels():
    from statsmodels.stats.inter_rater import cohens_kappa

    rng = np.random.default_rng(6)
    a = rng.integers(0, 4, 500)
    b = np.where(rng.random(500) < 0.6, a, rng.integers(0, 4, 500))
    table = np.zeros((4, 4))
    np.add.at(table, (a, b), 1)
    assert cohen_kappa(a, b) == pytest.approx(cohens_kappa(table).kappa)


def test_it_skips_frames_either_annotator_left_unlabelled():
    a = [0, 0, 1, 1, -1, -1]
    b = [0, 0, 1, 1, 0, 1]
    assert cohen_kappa(a, b) == 1.0
    assert math.isnan(cohen_kappa([-1, -1], [0, 1]))


def test_it_gives_kappa_one_when_both_use_one_label_everywhere():
    assert cohen_kappa([2, 2, 2], [2, 2, 2]) == 1.0


def test_it_reproduces_krippendorffs_published_nominal_example():
    # Krippendorff (2011), "Computing Krippendorff's alpha-reliability": 4 coders, 12 units,
    # nominal alpha = 0.743. Missing values are -1 here.
    m = -1
    data = [
        [1, 2, 3, 3, 2, 1, 4, 1, 2, m, m, m],
        [1, 2, 3, 3, 2, 2, 4, 1, 2, 5, m, 3],
        [m, 3, 3, 3, 2, 3, 4, 2, 2, 5, 1, m],
        [1, 2, 3, 3, 2, 4, 4, 1, 2, 5, 1, m],
    ]
    assert krippendorff_alpha(data) == pytest.approx(0.743, abs=5e-4)


def test_it_gives_alpha_one_for_identical_single_label_annotations():
    assert krippendorff_alpha([[0, 0, 0], [0, 0, -1]]) == 1.0
    assert math.isnan(krippendorff_alpha([[0, -1], [-1, 1]]))


def test_it_turns_segments_into_per_frame_codes():
    codes, names = label_codes([[(0, 3, "walk"), (3, 5, None)], [(0, 2, "punch"), (2, 5, "walk")]], 5)
    assert names == ["walk", "punch"]
    assert codes.tolist() == [[0, 0, 0, -1, -1], [1, 1, 0, 0, 0]]


def test_it_rejects_a_segment_outside_the_take():
    with pytest.raises(ValueError, match=r"segment \[3, 9\) of annotator 1 is outside the take's 5 frames"):
        label_codes([[(0, 5, "a")], [(0, 3, "a"), (3, 9, "b")]], 5)


def test_it_measures_per_label_overlap_as_intersection_over_union():
    # A: walk [0, 10), punch [10, 20); B: walk [0, 15), punch [15, 20).
    codes, names = label_codes([[(0, 10, "walk"), (10, 20, "punch")],
                                [(0, 15, "walk"), (15, 20, "punch")]], 20)
    overlap = label_overlap(codes, names)
    assert overlap["walk"] == {"overlap": pytest.approx(10 / 15), "frames": 15}
    assert overlap["punch"] == {"overlap": pytest.approx(5 / 10), "frames": 10}


def test_it_measures_a_segments_support_from_the_other_annotators():
    codes, _ = label_codes([[(0, 10, "walk")], [(0, 5, "walk"), (5, 10, "punch")],
                            [(0, 10, "walk")]], 10)
    # Others over [0, 10): annotator 1 agrees on 5 of 10 frames, annotator 2 on 10 of 10.
    assert segment_support(codes, 0, 0, 10) == pytest.approx(15 / 20)
    assert math.isnan(segment_support(codes[:1], 0, 0, 10))


def test_it_summarises_a_take_with_pairs_alpha_and_labels():
    segments = [[(0, 50, "a"), (50, 100, "b")], [(0, 52, "a"), (52, 100, "b")],
                [(0, 100, "a")]]
    cuts = [[50], [52], []]
    result = take_agreement(segments, cuts, n_frames=100, fps=100, tolerance_s=0.05)
    assert [(p["a"], p["b"]) for p in result["pairs"]] == [(0, 1), (0, 2), (1, 2)]
    assert [p["boundary"]["f1"] for p in result["pairs"]] == [1.0, 0.0, 0.0]
    assert result["mean_boundary_f1"] == pytest.approx(1 / 3)
    assert result["pairs"][0]["kappa"] == pytest.approx(cohen_kappa(
        [0] * 50 + [1] * 50, [0] * 52 + [1] * 48))
    assert -1 < result["alpha"] < 1
    assert set(result["per_label"]) == {"a", "b"}
