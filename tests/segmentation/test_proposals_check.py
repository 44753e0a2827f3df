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


def test_the_reviewed_label_of_each_stretch_matches_the_obvious_reading():
    import numpy as np

    rng = np.random.default_rng(3)
    for _ in range(50):
        edges = sorted({int(x) for x in rng.integers(1, 999, size=12)})
        bounds = [0, *edges, 1000]
        segments = [(a, b, str(rng.integers(1, 4)) if rng.random() < 0.7 else "")
                    for a, b in zip(bounds[:-1], bounds[1:], strict=True) if rng.random() < 0.8]
        stretches = sorted(proposals._bounds(segments, 1000))
        obvious = [next((lab for s, e, lab in segments if lab and s <= a and b <= e), "")
                   for a, b in zip(stretches[:-1], stretches[1:], strict=True)]
        assert proposals._truth(segments, stretches) == obvious
