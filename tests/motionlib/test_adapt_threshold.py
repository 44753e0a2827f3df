"""The first model format (motionlib.adapt ThresholdModel): stored models load and detect as
before, and its learner still learns what it learnt."""

import numpy as np
import pytest

from motionlib import metrics, synth
from motionlib.adapt import ExampleError, ThresholdModel, detect
from motionlib.adapt import fit_threshold_model as fit_cut_model
from tests.motionlib.adapt_examples import FPS, keyed_examples, take_with_cuts


def _signed_errors(cuts, truth, fps):
    ci, ti = metrics.match(cuts, truth, tolerance=int(fps))
    return (np.asarray(truth)[ti] - np.asarray(cuts)[ci]) / fps


def test_it_moves_placement_to_where_the_annotators_cut():
    # These annotators mark the onset of the next activity, 0.6 s after the cross-fade.
    late = int(0.6 * FPS)
    examples = [(take, cuts + late) for take, cuts in (take_with_cuts(1), take_with_cuts(2))]
    model = fit_cut_model(examples)
    take, cuts = take_with_cuts(3)
    zero_shot = np.median(_signed_errors(detect(take).cuts, cuts + late, FPS))
    adapted = np.median(_signed_errors(detect(take, model).cuts, cuts + late, FPS))
    assert zero_shot > 0.3
    assert abs(adapted) < 0.15


def test_it_learns_that_a_studio_cuts_nothing_in_such_takes():
    model = fit_cut_model([(take_with_cuts(4)[0], []), (take_with_cuts(5)[0], [])])
    assert len(detect(take_with_cuts(6)[0], model).cuts) == 0


def test_it_learns_the_shortest_activity_from_the_examples():
    short = dict(segment_seconds=(1.5, 2.5), duration=30.0)
    model = fit_cut_model([take_with_cuts(7, **short), take_with_cuts(8, **short)])
    assert model.min_segment_s < 1.5
    assert model.scale_min_s < 3.0  # windows short enough to see such an activity
    take, cuts = take_with_cuts(9, **short)
    found = metrics.boundary_scores(detect(take, model).cuts, cuts, fps=FPS, tolerance_s=0.5)
    zero_shot = metrics.boundary_scores(detect(take).cuts, cuts, fps=FPS, tolerance_s=0.5)
    assert found["recall"] > zero_shot["recall"]


def test_it_keeps_the_zero_shot_windows_without_short_activities():
    model = fit_cut_model([take_with_cuts(1), take_with_cuts(2)])
    assert (model.scale_min_s, model.scale_max_s) == (3.0, 6.0)


def test_it_counts_the_examples_it_learnt_from():
    model = fit_cut_model([take_with_cuts(1), take_with_cuts(2)])
    assert (model.n_takes, model.n_cuts) == (2, len(take_with_cuts(1)[1]) + len(take_with_cuts(2)[1]))


def test_it_round_trips_a_model_through_json():
    model = ThresholdModel(n_takes=2, n_cuts=9, threshold=0.2, prominence=0.1, min_segment_s=1.5,
                     scale_min_s=3.0, scale_max_s=6.0, placement="split", offset_s=-0.1)
    text = model.to_json()
    assert '"format": 1' in text
    assert ThresholdModel.from_json(text) == model


@pytest.mark.parametrize("text, fault", [
    ("{", "not JSON"),
    ('{"format": 2}', "format 2"),
    ('{"format": 3}', "format 3"),
    ('{"format": 1, "n_takes": 1, "n_cuts": 1, "threshold": "x", "min_segment_s": 1, '
     '"prominence": 1, "scale_min_s": 3, "scale_max_s": 6, "offset_s": 0, "placement": "pause"}', "threshold"),
    ('{"format": 1, "n_takes": 1, "n_cuts": 1, "threshold": 1, "min_segment_s": 1, '
     '"prominence": 1, "scale_min_s": 3, "scale_max_s": 6, "offset_s": 0, "placement": "middle"}', "placement"),
])
def test_it_refuses_a_stored_model_it_cannot_read(text, fault):
    with pytest.raises(ValueError, match=fault):
        ThresholdModel.from_json(text)


def test_it_reads_a_stored_model_from_before_the_prominence_test_as_it_was():
    text = ('{"format": 1, "n_takes": 1, "n_cuts": 4, "threshold": 0.3, "min_segment_s": 2, '
            '"scale_min_s": 3, "scale_max_s": 6, "offset_s": 0, "placement": "pause"}')
    assert ThresholdModel.from_json(text).prominence == 0.0


def test_it_refuses_a_cut_outside_the_example_take():
    take, _ = take_with_cuts(1, duration=20.0)
    with pytest.raises(ExampleError, match=f"cut {take.n_frames + 5} is outside"):
        fit_cut_model([(take, [100, take.n_frames + 5])])


def test_it_names_an_example_take_too_short_to_learn_from():
    take, _ = take_with_cuts(1, duration=20.0)
    with pytest.raises(ExampleError, match=r"synth-1: too short to learn from \(3 frames\)"):
        fit_cut_model([(take_with_cuts(2)[0], []), (take.slice(0, 3), [1])])


def test_it_refuses_an_empty_example_list():
    with pytest.raises(ExampleError, match="no example takes"):
        fit_cut_model([])


def test_it_detects_zero_shot_exactly_as_the_default_segmenter():
    from motionlib.segmenters.default import Default

    take, _ = take_with_cuts(1, duration=20.0)
    assert detect(take).cuts.tolist() == Default().fit_predict(take).cuts.tolist()


def _peaks(prominences, cuts):
    """One example's novelty peaks (every 100 frames) as the count sees them."""
    frames = 100 * np.arange(1, len(prominences) + 1)
    return frames, np.asarray(prominences, float), np.asarray(cuts), 10, frames


# At the zero-shot prominence (0.1) a usual example's peaks are its cuts; a higher
# prominence loses one. The unusual one holds weak peaks where its annotators cut nothing.
USUAL = _peaks([0.5, 0.5, 0.12, 0.05], [100, 200, 300])
UNUSUAL = _peaks([0.5, 0.15, 0.15, 0.15, 0.15], [100])


def test_one_unusual_example_among_several_does_not_move_the_count():
    from motionlib.adapt._threshold import _count

    # Summed over the four examples a prominence above 0.15 scores best (3.0 against 0:
    # the unusual one's four false peaks are four deletes), but only because of the
    # unusual one: chosen without it, the others keep 0.1.
    assert _count([USUAL, USUAL, USUAL, UNUSUAL], 0.1)[1] == 0.1


def test_examples_that_agree_still_move_the_count():
    from motionlib.adapt._threshold import _count

    assert _count([UNUSUAL, UNUSUAL, UNUSUAL], 0.1)[1] > 0.15
    assert _count([USUAL, USUAL, USUAL], 0.1)[1] == 0.1


def test_examples_move_the_count_from_a_zero_shot_without_the_prominence_test():
    from motionlib.adapt._threshold import _count

    with np.errstate(divide="raise"):
        assert _count([UNUSUAL, UNUSUAL, UNUSUAL], 0.0)[1] > 0.15
        # The usual examples' false peak (0.05) goes, their weakest cut (0.12) stays.
        assert 0.05 < _count([USUAL, USUAL, USUAL], 0.0)[1] <= 0.12


def test_the_count_keeps_weak_peaks_only_if_they_save_a_reviewer_edits():
    from motionlib.adapt._threshold import _count

    # Two strong peaks on cuts; five weak ones (0.2), two of them on the other two cuts.
    # Keeping the weak ones raises F1 (8/11 against 4/6) but costs three deletes to save
    # two inserts: the count drops them.
    example = _peaks([1.0, 1.0, 0.2, 0.2, 0.2, 0.2, 0.2], [100, 200, 300, 400])
    assert _count([example], 0.2)[1] > 0.2
    # Three of five true: they save a reviewer one edit, and stay.
    example = _peaks([1.0, 1.0, 0.2, 0.2, 0.2, 0.2, 0.2], [100, 200, 300, 400, 500])
    assert _count([example], 0.2)[1] == 0.2


def test_a_take_of_one_activity_weighs_its_false_peak_like_any_other_example():
    from motionlib.adapt._threshold import _count

    # A reviewed take labelled as one activity (no cut) where the detector found one peak,
    # beside a take of five cuts whose weakest true peak is 0.2. Counted per cut of its own
    # take, the one false peak would weigh as much as five of the other take's cuts and
    # push the count above 0.3, losing that cut everywhere; counted like any other edit it
    # weighs less than the cut.
    cuts = _peaks([0.5, 0.5, 0.5, 0.5, 0.2], [100, 200, 300, 400, 500])
    whole = _peaks([0.3], [])
    assert _count([cuts, whole], 0.1)[1] == 0.1
    # Three false peaks in it outweigh the one cut.
    assert _count([cuts, _peaks([0.3, 0.3, 0.3], [])], 0.1)[1] > 0.3


def test_two_examples_keep_the_fixed_prior():
    from motionlib.adapt._threshold import _count

    # Too few to leave one out: the fixed prior lets the two examples' sum decide.
    assert _count([USUAL, UNUSUAL], 0.1)[1] > 0.15


def test_a_studio_that_cuts_nothing_teaches_it_with_three_examples():
    model = fit_cut_model([(take_with_cuts(seed)[0], []) for seed in (4, 5, 10)])
    assert len(detect(take_with_cuts(6)[0], model).cuts) == 0



def test_a_refit_reads_only_the_examples_whose_study_is_not_stored():
    from dataclasses import replace

    from motionlib.adapt import MemoryStudies

    studies, reads = MemoryStudies(), []
    examples = keyed_examples((1, 2, 3), reads)
    first = fit_cut_model(examples, studies=studies)
    assert reads == [1, 2, 3] and set(studies.items) == {"take-1", "take-2", "take-3"}
    reads.clear()
    assert fit_cut_model(examples, studies=studies) == first
    assert reads == []
    # A review changes the cuts of one take: only that take is read and analysed again.
    examples[1] = replace(examples[1], cuts=examples[1].cuts[:-1])
    refit = fit_cut_model(examples, studies=studies)
    assert reads == [2]
    assert refit == fit_cut_model([(e.read(), e.cuts) for e in examples])


def test_a_study_made_with_other_settings_is_not_used():
    from motionlib.adapt import MemoryStudies

    studies, reads = MemoryStudies(), []
    fit_cut_model(keyed_examples((7, 8), reads), studies=studies)
    # A third example with a much shorter activity changes the minimum segment, and so
    # what every example's peaks are: all three are analysed again.
    short = keyed_examples((9,), reads, segment_seconds=(1.5, 2.5), duration=30.0)
    reads.clear()
    fit_cut_model(keyed_examples((7, 8), reads) + short, studies=studies)
    assert sorted(reads) == [7, 8, 9]


def test_examples_without_a_key_are_never_stored():
    from motionlib.adapt import MemoryStudies

    studies = MemoryStudies()
    fit_cut_model([take_with_cuts(1), take_with_cuts(2)], studies=studies)
    assert studies.items == {}


def test_it_starts_from_the_settings_it_is_given():
    model = fit_cut_model([take_with_cuts(1), take_with_cuts(2)], base={"threshold": 0.2, "min_segment_s": 1.0})
    assert model.threshold == 0.2
    assert model.min_segment_s <= 1.0  # never longer than where it started
    zero_shot = fit_cut_model([take_with_cuts(1), take_with_cuts(2)])
    assert (zero_shot.threshold, zero_shot.min_segment_s) == (0.1, 1.5)


def test_an_example_counts_both_sides_of_a_short_activity_the_detector_cuts():
    # 6 s, 1.8 s, 6 s: the long windows see the short activity as one peak, and the
    # detector's unmatched-poses step makes it two cuts; the study the count is learnt
    # from must hold both, where the detector places them, at the zero-shot prominence.
    from motionlib.adapt import Example, MemoryStudies
    from motionlib.adapt._threshold import matched_count
    from motionlib.segmenters.default import Default

    take, segments = synth.generate(seed=1, fps=FPS, plan=[("idle", 6.0), ("kick", 1.8),
                                                           ("walk", 6.0)])
    cuts = np.asarray([start for start, _, _ in segments[1:]], dtype=np.int64)
    assert matched_count(detect(take).cuts, cuts, int(FPS)) == 2
    studies = MemoryStudies()
    fit_cut_model([Example(name="short", cuts=cuts, fps=FPS, n_frames=take.n_frames,
                           read=lambda: take, key="short")], studies=studies)
    study = studies.items["short"][1]
    kept = study["placed_frames"][study["placed_prominence"] >=
                                  Default.params["prominence"].default]
    assert matched_count(kept, cuts, int(FPS)) == 2
    assert len(kept) == 2
