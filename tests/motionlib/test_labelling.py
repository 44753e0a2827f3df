"""The per-frame label model and the label-aware cut scorer (motionlib.labelling)."""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from motionlib import adapt, labelling, synth
from motionlib.labelling import FrameExample, _frames, evidence


def _example(segments, n=200, d=3, seed=0) -> FrameExample:
    """Samples every frame; the descriptor of a frame is its label's code plus noise."""
    rng = np.random.default_rng(seed)
    codes = {"": 0.0, "walk": 10.0, "jump": 20.0}
    x = np.zeros((n, d))
    for start, end, label in segments:
        x[start:end] = codes[label or ""]
    x += rng.normal(0, 0.1, x.shape)
    return FrameExample(np.arange(n), x, n, 10.0, list(segments))


SEGMENTS = [(0, 50, ""), (50, 120, "walk"), (120, 200, "jump")]


def test_frame_labels_mark_each_segment_and_leave_the_rest_unlabelled():
    names = ["", "jump", "walk"]
    got = labelling.frame_labels([(2, 4, "walk"), (5, 7, "jump"), (7, 8, None)], 9, names)
    assert_array_equal(got, [0, 0, 2, 2, 0, 1, 1, 0, 0])


def test_separable_labels_are_told_apart_at_every_frame():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    assert model.names == ["", "jump", "walk"]
    post = labelling.posterior(model, _example(SEGMENTS, seed=1))
    assert post.shape == (200, 3)
    assert_allclose(post.sum(axis=1), 1.0)
    assert_array_equal(post.argmax(axis=1)[[10, 80, 150]], [0, 2, 1])
    assert post[80, 2] > 0.9


def test_each_segment_gets_its_label_and_probability():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    post = labelling.posterior(model, _example(SEGMENTS, seed=1))
    got = labelling.propose(model, post, [50, 120])
    assert [label for label, _ in got] == [None, "walk", "jump"]
    assert all(p > 0.9 for _, p in got)


def test_leaving_out_the_only_take_leaves_the_prior():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    ex = _example(SEGMENTS, seed=1)
    post = labelling.posterior(model, ex, exclude=0)
    assert_allclose(post, np.tile(model.prior, (200, 1)))


def test_no_labelled_take_gives_no_model():
    assert labelling.fit_frame_model([]) is None
    assert labelling.fit_frame_model([_example([(0, 200, "")])]) is None


def test_fit_and_posterior_are_deterministic():
    examples = [_example(SEGMENTS, seed=s) for s in range(3)]
    a = labelling.posterior(labelling.fit_frame_model(examples), examples[0])
    b = labelling.posterior(labelling.fit_frame_model(examples), examples[0])
    assert_array_equal(a, b)


def test_a_stored_model_reads_back_the_same():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    back = labelling.FrameModel.from_json(model.to_json())
    ex = _example(SEGMENTS, seed=2)
    assert_allclose(labelling.posterior(back, ex), labelling.posterior(model, ex), atol=1e-5)
    with pytest.raises(ValueError, match="not a stored frame model"):
        labelling.FrameModel.from_json('{"format": 99}')


def test_a_taxonomy_change_relabels_without_retraining():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    ex = _example(SEGMENTS, seed=1)
    renamed = labelling.relabelled(model, {"walk": "stroll"})
    assert renamed.names == ["", "jump", "stroll"]
    assert labelling.propose(renamed, labelling.posterior(renamed, ex), [50, 120])[1][0] \
        == "stroll"
    merged = labelling.relabelled(model, {"walk": "move", "jump": "move"})
    assert merged.names == ["", "move"]
    assert [lab for lab, _ in labelling.propose(
        merged, labelling.posterior(merged, ex), [50, 120])] == [None, "move", "move"]
    retired = labelling.relabelled(model, {"jump": None})
    assert retired.names == ["", "walk"]
    assert labelling.propose(retired, labelling.posterior(retired, ex), [120])[1][0] is None


def test_evidence_sees_the_label_change_and_not_the_steady_middle():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    post = labelling.posterior(model, _example(SEGMENTS, seed=1))
    ev = evidence.evidence(post, [120, 85], 10.0, model)
    col = {name: i for i, name in enumerate(evidence.EVIDENCE)}
    assert ev[0, col["mix"]] > 0.9 and ev[1, col["mix"]] < 0.1
    assert ev[0, col["change"]] == 1 and ev[1, col["change"]] == 0
    assert ev[1, col["same"]] == 1
    assert ev[0, col["decoded_labelled"]] > 0.9


def test_decoding_ignores_a_flicker_shorter_than_usual():
    model = labelling.fit_frame_model([_example(SEGMENTS)])
    post = np.zeros((200, 3))
    post[:, 2] = 0.9
    post[:, 1] = 0.1
    post[100:103] = [0.0, 0.9, 0.1]  # 0.3 s of "jump" in a 7 s walk
    assert_array_equal(np.unique(labelling.decode(model, post, 10.0)), [2])


@pytest.fixture(scope="module")
def takes():
    out = []
    for seed in (1, 2, 3):
        take, segments = synth.generate(seed=seed, fps=30.0, duration=60.0)
        out.append((take, adapt.study(take), labelling.frame_example(take, segments),
                    np.asarray([s for s, _, _ in segments[1:]])))
    return out


def test_with_no_frame_model_the_scorer_keeps_the_cut_models_cuts_exactly(takes):
    zero = adapt.CutModel.zero_shot()
    for take, study, _, _ in takes:
        found, _ = evidence.select(zero, evidence.LabelCutModel.identity(), study, None)
        assert_array_equal(found, adapt.cuts_in(study, zero))
        assert_array_equal(found, adapt.detect(take).cuts)


def test_one_reviewed_take_keeps_the_scorer_at_the_cut_model(takes):
    zero = adapt.CutModel.zero_shot()
    (_, study, example, cuts), (_, other, other_example, _) = takes[0], takes[1]
    frames = labelling.fit_frame_model([example])
    joint = evidence.fit_label_cuts(zero, frames, [study], [example], [cuts], tolerance_s=1.0)
    assert_array_equal(joint.weights, evidence.LabelCutModel.identity().weights)
    post = labelling.posterior(frames, other_example)
    assert_array_equal(evidence.select(zero, joint, other, post)[0], adapt.cuts_in(other, zero))


def test_the_scorer_fitted_on_reviewed_takes_labels_the_segments(takes):
    zero = adapt.CutModel.zero_shot()
    studies = [t[1] for t in takes[:2]]
    examples = [t[2] for t in takes[:2]]
    frames = labelling.fit_frame_model(examples)
    joint = evidence.fit_label_cuts(zero, frames, studies, examples, [t[3] for t in takes[:2]],
                                    tolerance_s=1.0)
    again = evidence.fit_label_cuts(zero, frames, studies, examples, [t[3] for t in takes[:2]],
                                    tolerance_s=1.0)
    assert_array_equal(joint.weights, again.weights)
    post = labelling.posterior(frames, takes[2][2])
    found, prob = evidence.select(zero, joint, takes[2][1], post)
    assert len(found) == len(prob) and np.all((prob > 0) & (prob <= 1))
    proposals = labelling.propose(frames, post, found)
    assert len(proposals) == len(found) + 1
    assert {label for label, _ in proposals} <= set(synth.ACTIONS) | {None}


def test_the_rate_of_the_descriptors_is_the_models():
    take, _ = synth.generate(seed=4, fps=120.0, duration=10.0)
    samples, x = _frames.descriptors(take)
    assert np.all(np.diff(samples) == int(round(120 / _frames.RATE_HZ)))
    assert len(samples) == len(x)


def test_decoding_follows_the_order_the_reviewed_takes_showed():
    """Issue 47: the stretches' labels are decoded with the label order counted on the
    reviewed takes, so an ambiguous stretch takes the label the script puts there."""
    order = [(0, 40, ""), (40, 100, "walk"), (100, 200, "jump")]
    model = labelling.fit_frame_model([_example(order, seed=s) for s in range(3)])
    empty, jump, walk = (model.names.index(n) for n in ("", "jump", "walk"))
    assert model.transitions[walk, jump] == 3 and model.transitions[walk, empty] == 0
    post = np.zeros((200, 3))
    post[:40, empty] = post[40:100, walk] = 1.0
    # after the walk, jump or unlabelled: the frames cannot say (equal likelihood ratios)
    post[100:, [empty, jump]] = model.prior[[empty, jump]] / model.prior[[empty, jump]].sum()
    post = 0.98 * post + 0.02 / 3
    path = labelling.decode(model, post, 10.0)
    assert_array_equal(path[[20, 70, 150]], [empty, walk, jump])
    got = labelling.propose(model, post, [40, 100], fps=10.0)
    assert [label for label, _ in got] == [None, "walk", "jump"]


def test_sharpness_is_chosen_on_the_reviewed_takes_folds():
    examples = [_example(SEGMENTS, seed=s) for s in range(4)]
    model = labelling.fit_frame_model(examples, groups=["a", "a", "b", "b"])
    assert model.sharpness in labelling.SHARPNESS
    single = labelling.fit_frame_model(examples, groups=["a"] * 4)
    assert single.sharpness == labelling.SHARPNESS[0]


def test_a_stored_model_keeps_its_order_and_sharpness_and_old_ones_still_read():
    model = labelling.fit_frame_model([_example(SEGMENTS, seed=s) for s in range(2)])
    model.sharpness = 0.3
    back = labelling.FrameModel.from_json(model.to_json())
    assert_array_equal(back.transitions, model.transitions)
    assert_array_equal(back.starts, model.starts)
    assert back.sharpness == 0.3
    import json
    old = json.loads(model.to_json())
    for key in ("transitions", "starts", "sharpness"):
        del old[key]
    read = labelling.FrameModel.from_json(json.dumps(old))
    assert read.transitions is None and read.sharpness == 1.0
    assert len(labelling.decode(read, labelling.posterior(read, _example(SEGMENTS)), 10.0)) == 200


def test_merging_two_labels_merges_their_order_counts():
    model = labelling.fit_frame_model([_example(SEGMENTS, seed=s) for s in range(2)])
    merged = labelling.relabelled(model, {"walk": "move", "jump": "move"})
    assert merged.names == ["", "move"]
    assert_array_equal(merged.transitions, [[0, 2], [0, 0]])
    assert_array_equal(merged.starts, [2, 0])


def test_the_gate_chooses_among_its_options_on_the_reviewed_takes(takes):
    zero = adapt.CutModel.zero_shot()
    studies = [s for _, s, _, _ in takes]
    examples = [e for _, _, e, _ in takes]
    frames = labelling.fit_frame_model(examples)
    joint = evidence.fit_label_cuts(zero, frames, studies, examples,
                                    [c for _, _, _, c in takes], tolerance_s=1.0)
    assert joint.mode in evidence.MODES
    post = labelling.posterior(frames, examples[0])
    found, prob = evidence.select(zero, joint, studies[0], post)
    assert len(found) == len(prob) and np.all(np.diff(found) > 0)
