"""Learning a studio's cutting convention from reviewed takes (motionlib.adapt, format 2)."""

from dataclasses import replace

import numpy as np
import pytest

from motionlib import metrics
from motionlib.adapt import (
    CutModel,
    ExampleError,
    MemoryStudies,
    Refits,
    ThresholdModel,
    cuts_in,
    detect,
    example_study,
    fit_cut_model,
    score,
    study,
)
from tests.motionlib.adapt_examples import FPS, keyed_examples, take_with_cuts


def _f1(cuts, truth, tolerance_s=1.0):
    return metrics.boundary_scores(cuts, truth, fps=FPS, tolerance_s=tolerance_s)["f1"]


def test_the_prior_model_detects_exactly_the_zero_shot_cuts():
    for seed in (1, 2, 3):
        take, _ = take_with_cuts(seed)
        assert detect(take, CutModel.zero_shot()).cuts.tolist() == detect(take).cuts.tolist()


def test_it_cuts_a_new_take_closer_to_the_convention_it_was_taught():
    # Two studios cut the same activity changes, one at the cross-fade, the other 0.6 s
    # later (at the onset of the next activity).
    late = int(0.6 * FPS)
    takes = [take_with_cuts(seed) for seed in (1, 2, 4, 5)]
    at_change = fit_cut_model(takes)
    at_onset = fit_cut_model([(take, cuts + late) for take, cuts in takes])
    take, cuts = take_with_cuts(3)
    for model, taught, other in ((at_change, cuts, cuts + late),
                                 (at_onset, cuts + late, cuts)):
        found = detect(take, model).cuts
        assert _f1(found, taught, 0.25) > _f1(found, other, 0.25) + 0.15


def test_it_learns_that_a_studio_cuts_nothing_in_such_takes():
    model = fit_cut_model([(take_with_cuts(seed)[0], []) for seed in (4, 5, 10)])
    assert len(detect(take_with_cuts(6)[0], model).cuts) == 0


def test_it_learns_how_finely_a_studio_segments():
    long = dict(segment_seconds=(8.0, 12.0), duration=60.0)
    model = fit_cut_model([take_with_cuts(seed, **long) for seed in (1, 2, 3)])
    assert model.min_segment_s > 3.0


@pytest.mark.parametrize("mode", ["under", "over"])
def test_a_minority_of_bad_reviews_barely_moves_the_model(mode):
    takes = [take_with_cuts(seed, duration=40.0) for seed in range(20, 30)]
    rng = np.random.default_rng(0)

    def bad(take, cuts):
        if mode == "under":
            return cuts[::2]
        extra = rng.integers(1, take.n_frames - 1, size=len(cuts))
        return np.unique(np.concatenate([cuts, extra]))

    reviewed = [(take, bad(take, cuts) if i in (1, 4, 7) else cuts)
                for i, (take, cuts) in enumerate(takes)]
    clean, poisoned = fit_cut_model(takes), fit_cut_model(reviewed)
    assert poisoned.down_weighted >= 2
    for seed in (40, 41):
        take, cuts = take_with_cuts(seed)
        moved = _f1(detect(take, poisoned).cuts, cuts) - _f1(detect(take, clean).cuts, cuts)
        assert abs(moved) < 0.05


def test_it_round_trips_a_model_through_json():
    model = fit_cut_model([take_with_cuts(1), take_with_cuts(2), take_with_cuts(4)])
    text = model.to_json()
    assert '"format": 2' in text
    assert CutModel.from_json(text) == model


def test_it_reads_a_model_of_the_first_format_and_detects_with_it_as_before():
    from motionlib.adapt._threshold import detect_threshold

    text = ('{"format": 1, "n_takes": 2, "n_cuts": 9, "threshold": 0.2, "prominence": 0.1, '
            '"min_segment_s": 1.5, "scale_min_s": 3, "scale_max_s": 6, "offset_s": -0.1, '
            '"placement": "split"}')
    model = CutModel.from_json(text)
    assert isinstance(model, ThresholdModel)
    take, _ = take_with_cuts(3)
    assert detect(take, model).cuts.tolist() == detect_threshold(take, model).cuts.tolist()


@pytest.mark.parametrize("text, fault", [
    ("[1]", "JSON object"),
    ('{"format": 3}', "format 3"),
    ('{"format": 2, "features": ["zero_shot"]}', "features"),
])
def test_it_refuses_a_stored_model_it_cannot_read(text, fault):
    with pytest.raises(ValueError, match=fault):
        CutModel.from_json(text)


def test_it_refuses_weights_of_the_wrong_length():
    data = CutModel.zero_shot().to_json().replace('"weights": [', '"weights": [1.0, ')
    with pytest.raises(ValueError, match="weights must be 10 finite numbers"):
        CutModel.from_json(data)


def test_it_refuses_an_empty_example_list():
    with pytest.raises(ExampleError, match="no example takes"):
        fit_cut_model([])


def test_it_refuses_a_cut_outside_the_example_take():
    take, _ = take_with_cuts(1, duration=20.0)
    with pytest.raises(ExampleError, match=f"cut {take.n_frames + 5} is outside"):
        fit_cut_model([(take, [100, take.n_frames + 5])])


def test_it_names_an_example_take_too_short_to_learn_from():
    take, _ = take_with_cuts(1, duration=20.0)
    with pytest.raises(ExampleError, match=r"synth-1: too short to learn from \(3 frames\)"):
        fit_cut_model([(take_with_cuts(2)[0], []), (take.slice(0, 3), [1])])



def test_a_refit_reads_only_the_takes_it_has_not_studied():
    studies, reads = MemoryStudies(), []
    examples = keyed_examples((1, 2, 3), reads)
    first = fit_cut_model(examples, studies=studies)
    reads.clear()
    assert fit_cut_model(examples, studies=studies) == first
    # A review changes one take's cuts: its candidates stand as they were.
    examples[1] = replace(examples[1], cuts=examples[1].cuts[:-1])
    changed = fit_cut_model(examples, studies=studies)
    assert changed == fit_cut_model([(e.read(), e.cuts) for e in examples])
    reads.clear()
    fit_cut_model(examples + keyed_examples((4,), reads), studies=studies)
    assert reads == [4]


def test_detection_from_stored_candidates_equals_detection_from_the_take():
    model = fit_cut_model([take_with_cuts(1), take_with_cuts(2), take_with_cuts(4)])
    take, _ = take_with_cuts(3)
    assert cuts_in(study(take), model).tolist() == detect(take, model).cuts.tolist()


def test_an_examples_study_is_read_from_where_the_fit_kept_it():
    studies, reads = MemoryStudies(), []
    examples = keyed_examples((1, 2, 3), reads)
    model = fit_cut_model(examples, studies=studies)
    reads.clear()
    arrays = example_study(examples[0], studies=studies)
    assert reads == []  # the take is not read again
    assert cuts_in(arrays, model).tolist() == detect(examples[0].read(), model).cuts.tolist()
    zero = cuts_in(arrays, CutModel.zero_shot()).tolist()
    assert zero == detect(examples[0].read()).cuts.tolist()


def test_refits_start_from_the_full_fit_and_leave_one_example_out():
    examples = [take_with_cuts(seed) for seed in (1, 2, 4, 5)]
    refits = Refits(examples)
    assert refits.model == fit_cut_model(examples)
    without = refits.without(1)
    assert (without.n_takes, without.n_cuts) == (3, sum(len(c) for i, (_, c) in
                                                         enumerate(examples) if i != 1))
    # Below three examples a refit has nothing to keep: it is the fit on the others.
    assert Refits(examples[:3]).without(0) == fit_cut_model(examples[1:3])
    assert Refits(examples[:1]).without(0) is None


def test_it_scores_a_model_on_a_reviewed_take():
    take, cuts = take_with_cuts(3)
    found = detect(take).cuts
    figure = score(None, take, cuts, tolerance_s=1.0)
    assert figure["f1"] == pytest.approx(_f1(found, cuts))
    assert figure["edits_per_cut"] == pytest.approx(
        metrics.edit_cost(found, cuts, fps=FPS)["edits_per_cut"])
    assert (figure["n_cuts"], figure["n_true"]) == (len(found), len(cuts))
