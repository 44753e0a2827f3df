import dataclasses

import numpy as np
import pytest

from motionlib import metrics, synth
from motionlib.segmenters import ParamError, get_segmenter, list_segmenters
from motionlib.segmenters.base import Segmentation, Segmenter

METHODS = ["default", "bone_angle", "joint_distance_pca", "ppca"]


@pytest.fixture(scope="module")
def synth_takes():
    return [synth.generate(seed=seed, fps=120.0) for seed in range(3)]


def mean_scores(name, takes, **params):
    rows = []
    for take, segments in takes:
        truth = [start for start, _, _ in segments[1:]]
        cuts = get_segmenter(name)(**params).fit_predict(take).cuts
        rows.append(metrics.boundary_scores(cuts, truth, fps=take.fps, tolerance_s=1.0))
    return {k: np.mean([r[k] for r in rows]) for k in ("precision", "recall")}


def test_it_lists_every_method_with_its_schema_default_first():
    names = [cls.name for cls in list_segmenters()]
    assert names[0] == "default"
    assert sorted(names) == sorted(METHODS)
    for cls in list_segmenters():
        assert cls.title and cls.description and cls.params
        for key, spec in cls.schema()["params"].items():
            assert spec["type"] in ("float", "int", "bool"), key
            assert spec["min"] <= spec["default"] <= spec["max"], key


def test_it_names_an_unknown_method_and_the_valid_ones():
    with pytest.raises(ParamError, match=r"method: unknown segmenter 'nope' \(valid: default, "):
        get_segmenter("nope")


def test_it_fills_defaults_and_coerces_strings():
    values = get_segmenter("bone_angle").validate_params({"param": "0.25"})
    assert values == {"param": 0.25, "cutoff_hz": 1.0}
    assert get_segmenter("joint_distance_pca").validate_params({"span": "41"})["span"] == 41


def test_it_names_the_parameter_and_value_out_of_range():
    with pytest.raises(ParamError) as err:
        get_segmenter("bone_angle").validate_params({"param": 1.5})
    assert str(err.value) == "param: must be between 0 and 1, got 1.5"


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"span": 4.5}, "span: must be an integer, got 4.5"),
        ({"span": "many"}, "span: must be an integer, got 'many'"),
        ({"delta": "nan"}, "delta: must be a finite number, got 'nan'"),
        ({"delta": True}, "delta: must be a number, got True"),
        ({"spam": 1}, "spam: unknown parameter for method 'joint_distance_pca' (valid: "),
    ],
)
def test_it_rejects_bad_parameter_values(params, message):
    with pytest.raises(ParamError) as err:
        get_segmenter("joint_distance_pca").validate_params(params)
    assert str(err.value).startswith(message)


def test_it_reports_bad_parameters_at_fit_not_init(synth_takes):
    seg = get_segmenter("default")(threshold=-1)  # __init__ only stores
    with pytest.raises(ParamError, match="threshold: must be between 0 and 2, got -1"):
        seg.fit(synth_takes[0][0])


def test_it_refuses_predict_before_fit():
    with pytest.raises(RuntimeError, match="before fit"):
        get_segmenter("default")().predict()


class Sloppy(Segmenter):
    """Returns cuts out of order, duplicated, outside the take, and odd confidences."""

    name = "sloppy"

    def _segment(self, take, **params):
        cuts = [50, 0, 10, 10, take.n_frames, 30]
        return Segmentation(cuts=np.array(cuts), confidence=np.array([0.2, 0.9, 1.5, 0.4, 0.5, -0.3]))


def test_it_sorts_dedupes_and_clips_what_a_method_returns(synth_takes):
    result = Sloppy().fit_predict(synth_takes[0][0])
    assert result.cuts.tolist() == [10, 30, 50]
    assert result.confidence.tolist() == [1.0, 0.0, 0.2]
    assert result.timings["total"] > 0


# Sorted interior cuts and confidence in [0, 1] are enforced by Segmenter.fit for every
# method (tested above); the signals are each method's own. A take that starts with a
# rest pose is detected from the frame after it, and its signals still cover every frame.
@pytest.mark.parametrize("rest_pose_frame", [None, 0])
@pytest.mark.parametrize("name", METHODS)
def test_it_returns_a_finite_signal_value_per_frame(name, rest_pose_frame, synth_takes):
    take = dataclasses.replace(synth_takes[0][0], rest_pose_frame=rest_pose_frame)
    result = get_segmenter(name)().fit_predict(take)
    assert len(result.cuts) > 0
    assert result.signals and all(s.shape == (take.n_frames,) for s in result.signals.values())
    assert all(np.isfinite(s).all() for s in result.signals.values())


@pytest.mark.parametrize(
    ("name", "min_recall"),
    [("default", 0.9), ("bone_angle", 0.9), ("joint_distance_pca", 0.8), ("ppca", 0.6)],
)
def test_it_finds_the_true_boundaries_of_synthetic_takes(name, min_recall, synth_takes):
    assert mean_scores(name, synth_takes)["recall"] >= min_recall


def test_it_proposes_few_false_cuts_by_default(synth_takes):
    assert mean_scores("default", synth_takes)["precision"] >= 0.9


def test_it_keeps_working_at_another_frame_rate():
    takes = [synth.generate(seed=seed, fps=60.0) for seed in range(3)]
    scores = mean_scores("default", takes)
    assert scores["recall"] >= 0.9 and scores["precision"] >= 0.9


def test_it_proposes_fewer_cuts_with_a_higher_threshold(synth_takes):
    # The threshold alone: the support test drops this take's weakest peak (idle into
    # walk) at either threshold.
    take, _ = synth_takes[0]
    strict = get_segmenter("default")(threshold=0.5, support=0.0).fit_predict(take)
    loose = get_segmenter("default")(threshold=0.05, support=0.0).fit_predict(take)
    assert len(strict.cuts) < len(loose.cuts)


def test_it_gives_stronger_changes_higher_confidence(synth_takes):
    take, _ = synth_takes[0]
    result = get_segmenter("default")().fit_predict(take)
    novelty = result.signals["novelty"]
    order = np.argsort(result.confidence)
    peaks = [novelty[max(0, c - 60) : c + 60].max() for c in result.cuts[order]]
    assert peaks == sorted(peaks)


def test_it_swings_more_candidates_through_with_a_looser_test(synth_takes):
    take, _ = synth_takes[0]
    tight = get_segmenter("bone_angle")(param=0.1).fit_predict(take)
    loose = get_segmenter("bone_angle")(param=0.9).fit_predict(take)
    assert set(tight.cuts.tolist()) < set(loose.cuts.tolist())


def test_it_rejects_scales_in_the_wrong_order(synth_takes):
    seg = get_segmenter("default")(scale_min_s=4.0, scale_max_s=2.0)
    with pytest.raises(ParamError, match=r"scale_max_s: must be at least scale_min_s \(4\), got 2"):
        seg.fit(synth_takes[0][0])


def test_it_moves_a_cut_to_a_nearby_pause():
    from motionlib.segmenters.default._placement import settle_frame

    speed = np.full(1000, 10.0)
    speed[530] = 1.0
    assert settle_frame(speed, 500, radius=60, context=300) == 530


def test_it_leaves_a_cut_where_nothing_pauses():
    from motionlib.segmenters.default._placement import settle_frame

    speed = 10.0 + np.sin(np.arange(1000) / 10.0)  # slows a little, never stops
    assert settle_frame(speed, 500, radius=60, context=300) == 500


@pytest.mark.parametrize("name", METHODS)
@pytest.mark.parametrize("n_frames", [1, 2, 13, 200])
def test_it_handles_takes_too_short_to_cut(name, n_frames, synth_takes):
    take = synth_takes[0][0].slice(0, n_frames)
    result = get_segmenter(name)().fit_predict(take)
    assert all(len(s) == n_frames for s in result.signals.values())
    if name == "default":
        assert len(result.cuts) == 0  # 1.7 s is shorter than one minimum segment


def test_it_scores_every_split_by_the_kernel_variance_it_leaves():
    from motionlib.segmenters.default._placement import split_gains

    x = np.random.default_rng(0).standard_normal((23, 4))
    gamma = 0.3
    k = np.exp(-gamma * ((x[:, None] - x[None, :]) ** 2).sum(axis=-1))

    def within_variance(t):  # slow oracle: each segment's kernel variance, summed
        return sum(
            len(idx) - k[np.ix_(idx, idx)].sum() / len(idx)
            for idx in (np.arange(t), np.arange(t, len(x)))
        )

    expected = [len(x) - within_variance(t) for t in range(1, len(x))]
    np.testing.assert_allclose(split_gains(x, gamma), expected, rtol=1e-12)


@pytest.mark.parametrize("step", [1, 4])
def test_it_splits_two_pose_distributions_where_they_meet(step):
    from motionlib.segmenters.default._placement import best_split

    rng = np.random.default_rng(1)
    x = np.concatenate([rng.normal(0.0, 1.0, (400, 3)), rng.normal(1.5, 1.0, (400, 3))])
    split = best_split(x, 380, 100, 700, step=step, radius=60, gamma=0.2)
    assert abs(split - 400) <= step


def test_it_searches_for_the_split_only_within_the_radius():
    from motionlib.segmenters.default._placement import best_split

    x = np.concatenate([np.zeros((100, 2)), np.ones((100, 2))])
    assert best_split(x, 150, 0, 200, step=1, radius=20, gamma=1.0) == 130
    assert best_split(x, 150, 149, 151, step=4, radius=20, gamma=1.0) == 150  # too short


def test_it_finds_the_turning_points_of_a_periodic_movement():
    from motionlib.segmenters.default._placement import turning_points

    fps = 120.0
    t = np.arange(int(4 * fps)) / fps
    x = np.stack([np.sin(2 * np.pi * 0.5 * t), np.zeros_like(t)], axis=1)  # a 2 s swing
    # The swing stops at its extremes, every second from 0.5 s on.
    np.testing.assert_array_equal(turning_points(x, fps=fps), [60, 180, 300, 420])


def test_it_moves_a_cut_to_the_nearest_turning_point_within_reach():
    from motionlib.segmenters.default._placement import nearest

    points = np.array([100, 180, 260])
    assert nearest(points, 200, radius=30) == 180
    assert nearest(points, 220, radius=30) == 220  # both are 40 frames away
    assert nearest(np.zeros(0, np.int64), 220, radius=30) == 220


@pytest.mark.parametrize("fps", [120.0, 30.0])
def test_it_places_synthetic_cuts_close_to_the_truth(fps):
    errors = []
    for seed in range(3):
        take, segments = synth.generate(seed=seed, fps=fps)
        truth = [start for start, _, _ in segments[1:]]
        cuts = get_segmenter("default")().fit_predict(take).cuts
        errors.append(metrics.median_error_s(cuts, truth, fps=fps))
    # The truth is the middle of a 0.5 s cross-fade; the cut goes to where the motion
    # turns, at most a quarter of a ~1 s movement cycle away.
    assert np.mean(errors) <= 0.3


@pytest.mark.parametrize("fps", [120.0, 10.0])
def test_it_places_cuts_with_the_finest_allowed_parameters(fps):
    take, _ = synth.generate(seed=0, fps=fps)
    params = {"min_segment_s": 0.1, "rate_hz": 60.0, "scale_min_s": 0.2, "scale_max_s": 0.2}
    result = get_segmenter("default")(**params).fit_predict(take)
    assert len(result.cuts) > 0
    assert np.all((result.cuts >= 0) & (result.cuts < take.n_frames))
