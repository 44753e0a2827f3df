"""Stored cut models keep detecting as they did, and the learner keeps learning the same
models: ``stored_cut_models.json`` holds models as the service stores them (``to_json``)
and what each cut on seeded synthetic takes, recorded before the learner was rebuilt on
the detector's public steps and format 1 shrank to a loader."""

import json
from pathlib import Path

import numpy as np
import pytest

from motionlib.adapt import CutModel, Refits, ThresholdModel, detect
from tests.motionlib.adapt_examples import take_with_cuts

STORED = json.loads((Path(__file__).parent / "stored_cut_models.json").read_text())
SHORT = {"segment_seconds": (1.5, 3.0), "duration": 40.0}
TAKES = {"synth 3": (3, {}), "synth 6": (6, {}), "synth 7 short": (7, SHORT)}


def _detected(model, name):
    seed, kw = TAKES[name]
    return detect(take_with_cuts(seed, **kw)[0], model)


def _assert_detects(model, detects):
    for name, expected in detects.items():
        result = _detected(model, name)
        assert result.cuts.tolist() == expected["cuts"], name
        np.testing.assert_allclose(result.confidence, expected["confidence"], atol=1e-9)


@pytest.mark.parametrize("stored", STORED["format1"], ids=lambda s: s["name"])
def test_a_stored_format_1_model_loads_and_cuts_exactly_as_when_it_was_stored(stored):
    model = CutModel.from_json(stored["model"])
    assert isinstance(model, ThresholdModel)
    _assert_detects(model, stored["detects"])


def test_the_stored_format_1_models_cut_differently_from_each_other():
    # The fixture can tell a loader that ignored a setting from one that reads it.
    cuts = {json.dumps(s["detects"]["synth 7 short"]["cuts"]) for s in STORED["format1"]}
    assert len(cuts) >= 4


def _weights_equal(text, expected):
    got, want = json.loads(text), json.loads(expected)
    np.testing.assert_allclose(got.pop("weights"), want.pop("weights"), rtol=0, atol=1e-9)
    assert got == want


@pytest.mark.parametrize("stored", STORED["format2"], ids=lambda s: s["name"])
def test_the_learner_learns_the_same_model_from_the_same_reviewed_takes(stored):
    kw = SHORT if stored["short"] else {}
    examples = [(take, cuts + stored["shift"])
                for take, cuts in (take_with_cuts(seed, **kw) for seed in stored["seeds"])]
    refits = Refits(examples)
    _weights_equal(refits.model.to_json(), stored["model"])
    _weights_equal(refits.without(0).to_json(), stored["without_first"])
    _assert_detects(refits.model, stored["detects"])
    _assert_detects(CutModel.from_json(stored["model"]), stored["detects"])
