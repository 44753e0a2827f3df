import numpy as np
import pytest
from numpy.testing import assert_allclose

from motionlib import features

JOINTS = {
    "root": 0, "chest": 1, "left_shoulder": 2, "left_elbow": 3, "left_wrist": 4,
    "right_shoulder": 5, "right_elbow": 6, "right_wrist": 7, "left_hip": 8, "left_knee": 9,
    "left_ankle": 10, "right_hip": 11, "right_knee": 12, "right_ankle": 13, "head": 14,
}


def t_pose() -> np.ndarray:
    """One frame (1, 15, 3): arms straight out sideways, legs straight down, Y up."""
    p = np.zeros((15, 3))
    p[1] = (0, 5, 0)
    p[2], p[3], p[4] = (1, 5, 0), (3, 5, 0), (5, 5, 0)
    p[5], p[6], p[7] = (-1, 5, 0), (-3, 5, 0), (-5, 5, 0)
    p[8], p[9], p[10] = (1, 0, 0), (1, -4, 0), (1, -8, 0)
    p[11], p[12], p[13] = (-1, 0, 0), (-1, -4, 0), (-1, -8, 0)
    p[14] = (0, 7, 0)
    return p[None]


def slow_lowess(y: np.ndarray, span: int) -> np.ndarray:
    """The obvious definition: for each sample, its `span` nearest samples, tricube
    weights scaled by the farthest of them, weighted straight-line fit, evaluated there."""
    n = len(y)
    span -= 1 - span % 2
    out = np.empty(n)
    for i in range(n):
        lo = min(max(i - span // 2, 0), n - span)
        x = np.arange(lo, lo + span, dtype=float)
        d = np.abs(x - i)
        w = (1 - (d / d.max()) ** 3) ** 3
        coef = np.polyfit(x, y[lo : lo + span], 1, w=np.sqrt(w))
        out[i] = np.polyval(coef, i)
    return out


@pytest.mark.parametrize("span", [5, 8, 21, 50])
def test_it_smooths_like_the_slow_lowess_oracle(span):
    y = np.random.default_rng(span).normal(size=120).cumsum()
    assert_allclose(features.lowess(y, span), slow_lowess(y, span), atol=1e-9)


def test_it_smooths_like_statsmodels_lowess_without_robustness():
    from statsmodels.nonparametric.smoothers_lowess import lowess as sm_lowess

    y = np.random.default_rng(1).normal(size=300).cumsum()
    ours = features.lowess(y, 31)
    theirs = sm_lowess(y, np.arange(300.0), frac=31 / 300, it=0, delta=0, return_sorted=False)
    assert_allclose(ours, theirs, atol=1e-9)


def test_it_reproduces_a_straight_line_exactly():
    y = 3.0 - 0.25 * np.arange(100)
    assert_allclose(features.lowess(y, 15), y, atol=1e-10)


def test_it_returns_short_input_unchanged():
    assert_allclose(features.lowess(np.array([1.0, 5.0]), 31), [1.0, 5.0])


def test_it_measures_limb_angles_against_the_spine():
    angles = features.bone_angles(t_pose(), JOINTS)[0]
    # Arms point sideways (90°), legs point down along the spine's opposite (180°).
    assert_allclose(angles[:4], np.pi / 2, atol=1e-12)
    assert_allclose(angles[4:], np.pi, atol=1e-12)


def test_it_measures_the_nine_documented_distances():
    d = features.joint_distances(t_pose(), JOINTS)[0]
    assert d.shape == (9,)
    assert d[0] == pytest.approx(10.0)  # hand to hand
    assert d[1] == pytest.approx(2.0)  # foot to foot


def test_it_ignores_where_the_body_stands_and_faces():
    rng = np.random.default_rng(0)
    frames = t_pose().repeat(5, axis=0) + rng.normal(scale=0.3, size=(5, 15, 3))
    angle = rng.uniform(-np.pi, np.pi, size=5)
    c, s = np.cos(angle), np.sin(angle)
    turned = frames.copy()
    turned[..., 0] = c[:, None] * frames[..., 0] + s[:, None] * frames[..., 2]
    turned[..., 2] = -s[:, None] * frames[..., 0] + c[:, None] * frames[..., 2]
    turned += rng.normal(scale=50, size=(5, 1, 3))
    assert_allclose(
        features.body_frame_positions(turned, JOINTS),
        features.body_frame_positions(frames, JOINTS),
        atol=1e-9,
    )


def test_it_finds_alternating_extrema_of_a_sine():
    t = np.arange(0, 4, 0.01)
    idx, is_max = features.local_extrema(np.sin(2 * np.pi * t))
    assert len(idx) == 8
    assert is_max.tolist() == [True, False] * 4
    assert_allclose(t[idx[:2]], [0.25, 0.75], atol=0.011)


def test_it_passes_one_sided_extrema_only():
    y = np.array([0.0, 10.0, 9.0, 10.0, 0.0, 5.0, 0.0])
    idx, _ = features.local_extrema(y)
    assert idx.tolist() == [1, 2, 3, 4, 5]
    passed, strength = features.swing_test(y, idx, 0.5)
    # Swings (left, right): 1: (10, 1), 2: (1, 1), 3: (1, 10), 4: (10, 5), 5: (5, 5).
    assert passed.tolist() == [True, False, True, True, False]
    assert strength[0] == pytest.approx(0.9)


def test_it_removes_frequencies_above_the_cutoff():
    t = np.arange(0, 10, 1 / 120)
    slow, fast = np.sin(2 * np.pi * 0.2 * t), np.sin(2 * np.pi * 20 * t)
    out = features.lowpass(slow + fast, fps=120, cutoff_hz=2.0)
    assert np.abs(out - slow)[120:-120].max() < 0.02


def test_it_reports_speed_in_units_per_second():
    x = np.arange(10.0)[:, None] * 2.0  # 2 units per frame
    assert_allclose(features.frame_speed(x, fps=30), 60.0)


def test_the_heading_is_the_ground_plane_vector_over_its_length():
    rng = np.random.default_rng(5)
    dx, dz = rng.normal(size=200) * 10.0 ** rng.integers(-3, 4, 200), rng.normal(size=200)
    c, s = features.heading_cos_sin(dx, dz)
    angle = np.arctan2(dz, dx)
    assert_allclose(c, np.cos(angle), rtol=0, atol=1e-15)
    assert_allclose(s, np.sin(angle), rtol=0, atol=1e-15)


def test_a_zero_hip_axis_leaves_the_frame_unturned():
    c, s = features.heading_cos_sin(np.array([0.0, -0.0, 1.0]), np.array([0.0, 0.0, 0.0]))
    np.testing.assert_array_equal(c, [1.0, 1.0, 1.0])
    np.testing.assert_array_equal(s, [0.0, 0.0, 0.0])
