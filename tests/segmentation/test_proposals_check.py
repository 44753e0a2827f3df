"""The held-out check a frame model passes before its proposals are shown (issue 47): its
proposals, each reviewed take scored by the model without that take's own points, must
match more reviewed frames than the best constant proposal would."""

from motionlib import labelling, synth
from segmentation.similar import proposals

SEEDS = (92, 93, 95)


def examples(name=lambda seed, action: action):
    out = []
    for seed in SEEDS:
        take, segments = synth.generate(seed=seed, fps=120.0, duration=30.0)
        out.append(labelling.frame_example(take, [(a, b, name(seed, lab)) for a, b, lab in segments]))
    return out


def test_a_model_of_consistent_labels_passes_and_is_kept():
    chosen = examples()
    check = proposals.held_out(labelling.fit_frame_model(chosen), chosen)
    assert check.takes == len(SEEDS)
    assert check.accuracy > check.constant
    assert proposals.checked_fit(chosen) is not None


def test_a_model_whose_labels_say_nothing_of_the_motion_is_refused():
    """Each take names the same actions differently (a cycle of the action list shifted by
    take): held out, the model names a take's motion as the other takes did, which is
    wrong, and proposing the commonest label everywhere would do better."""
    actions = list(synth.ACTIONS)

    def shifted(seed, action):
        return actions[(actions.index(action) + SEEDS.index(seed) * 2 + 1) % len(actions)]

    chosen = examples(shifted)
    check = proposals.held_out(labelling.fit_frame_model(chosen), chosen)
    assert check.accuracy <= check.constant, (check.accuracy, check.constant)
    assert proposals.checked_fit(chosen) is None


def test_a_single_reviewed_take_leaves_nothing_to_hold_out_and_proposes_nothing():
    assert proposals.checked_fit(examples()[:1]) is None
