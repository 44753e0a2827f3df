"""The first model format (motionlib.adapt ThresholdModel), a loader only: stored models
load and detect as before (what each stored model cuts: test_adapt_stored.py), and a model
it cannot read is refused by name."""

import pytest

from motionlib.adapt import CutModel, ThresholdModel, detect
from motionlib.adapt._threshold import detect_threshold
from motionlib.segmenters.default import Default
from tests.motionlib.adapt_examples import take_with_cuts


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


def test_a_stored_model_detects_with_its_own_settings():
    # Its windows, count and placement replace the detector's: cut where the detector
    # with those settings places each cut at the model's step, moved by its offset.
    model = ThresholdModel(n_takes=2, n_cuts=9, threshold=0.1, prominence=0.05,
                           min_segment_s=1.0, scale_min_s=2.0, scale_max_s=4.0,
                           placement="split", offset_s=0.5)
    take, _ = take_with_cuts(3)
    p = Default.validate_params(model.params())
    analysis = Default.analyse(take, p)
    placed = Default.place(analysis, Default.peaks(analysis, p), p)
    expected = placed.stages["split"] + analysis.first + int(round(0.5 * take.fps))
    assert detect(take, model).cuts.tolist() == expected[expected < take.n_frames].tolist()


def test_any_stored_format_loads_through_the_cut_model():
    text = ThresholdModel(n_takes=1, n_cuts=2, threshold=0.2, prominence=0.1,
                          min_segment_s=1.5, scale_min_s=3.0, scale_max_s=6.0,
                          placement="onset", offset_s=0.0).to_json()
    assert CutModel.from_json(text) == ThresholdModel.from_json(text)


def test_it_detects_zero_shot_exactly_as_the_default_segmenter():
    take, _ = take_with_cuts(1, duration=20.0)
    assert detect(take).cuts.tolist() == Default().fit_predict(take).cuts.tolist()
    assert detect_threshold(take).cuts.tolist() == detect(take).cuts.tolist()
