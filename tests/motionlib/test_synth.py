"""motionlib.synth: seeded takes of known actions with known boundaries."""

import numpy as np
import pytest

import motionlib
from motionlib import synth


def test_it_returns_the_same_take_for_the_same_seed():
    a, segments_a = synth.generate(seed=7, duration=30.0)
    b, segments_b = synth.generate(seed=7, duration=30.0)
    np.testing.assert_array_equal(a.channels, b.channels)
    assert segments_a == segments_b


def test_it_returns_a_different_take_for_another_seed():
    a, _ = synth.generate(seed=1, duration=30.0)
    b, _ = synth.generate(seed=2, duration=30.0)
    assert not np.allclose(a.channels, b.channels)


def test_it_covers_the_take_with_contiguous_segments_of_changing_labels():
    take, segments = synth.generate(seed=4, duration=90.0, fps=60.0)
    assert take.n_frames == 90 * 60 and take.fps == 60.0
    assert segments[0][0] == 0 and segments[-1][1] == take.n_frames
    for (_, stop, label), (start, _, next_label) in zip(segments, segments[1:], strict=False):
        assert stop == start and label != next_label
    assert {label for *_, label in segments} <= set(synth.ACTIONS)


def test_it_makes_the_requested_number_of_segments_from_the_requested_actions():
    _, segments = synth.generate(seed=0, n_segments=5, actions=("squat", "punch"))
    assert len(segments) == 5
    labels = [label for *_, label in segments]
    assert set(labels) == {"squat", "punch"}
    assert all(a != b for a, b in zip(labels, labels[1:], strict=False))


def test_it_builds_a_skeleton_with_every_canonical_part():
    take, _ = synth.generate(seed=0, n_segments=2)
    assert set(motionlib.canonical_indices(take)) == set(motionlib.CANONICAL_PARTS)
    assert take.rest_pose_frame is None


def test_it_keeps_the_feet_near_the_floor_and_the_head_up():
    take, _ = synth.generate(seed=5, duration=60.0)
    positions = motionlib.forward_kinematics(take)
    at = motionlib.canonical_indices(take)
    height = motionlib.skeleton_height(take)
    lowest_foot = positions[:, [at["left_ankle"], at["right_ankle"]], 1].min(axis=1)
    assert np.median(lowest_foot) < 0.1 * height
    assert np.all(positions[:, at["head"], 1] > positions[:, at["root"], 1])


def test_it_makes_actions_differ_in_their_joint_angles():
    take, segments = synth.generate(seed=6, n_segments=14, segment_seconds=(3.0, 4.0))
    means = {}
    for start, stop, label in segments:
        means.setdefault(label, []).append(take.channels[start:stop, 6:].std(axis=0))
    profiles = {label: np.mean(v, axis=0) for label, v in means.items()}
    labels = sorted(profiles)
    for i, a in enumerate(labels):
        for b in labels[i + 1:]:
            assert np.abs(profiles[a] - profiles[b]).max() > 5.0, (a, b)


def test_it_changes_pose_statistics_at_each_boundary():
    take, segments = synth.generate(seed=8, n_segments=6)
    second = int(take.fps)
    for (_, stop, _), _next in zip(segments, segments[1:], strict=False):
        before = take.channels[stop - 3 * second:stop - second, 6:]
        after = take.channels[stop + second:stop + 3 * second, 6:]
        assert np.abs(before.mean(0) - after.mean(0)).max() + \
            np.abs(before.std(0) - after.std(0)).max() > 5.0


def test_it_generates_a_five_minute_take_at_120_fps():
    # Its speed is reported by `python -m benchmarks speed-io`, not asserted here.
    take, segments = synth.generate(seed=0, fps=120.0, duration=300.0)
    assert take.n_frames == 36000 and take.channels.shape == (36000, take.skeleton.n_channels)
    assert len(segments) >= 300 / 8


@pytest.mark.parametrize("kwargs, message", [
    ({"fps": 0}, "fps must be positive"),
    ({"duration": -1.0}, "duration must be positive"),
    ({"actions": ("squat", "moonwalk")}, "actions must be at least two of"),
    ({"actions": ("squat",)}, "actions must be at least two of"),
    ({"segment_seconds": (5.0, 2.0)}, "segment_seconds"),
    ({"transition_seconds": 10.0}, "transition_seconds"),
])
def test_it_rejects_bad_parameters_naming_them(kwargs, message):
    with pytest.raises(ValueError, match=message):
        synth.generate(seed=0, **kwargs)


def test_it_cuts_without_a_transition_when_asked():
    take, segments = synth.generate(seed=3, n_segments=3, transition_seconds=0.0,
                                    noise_degrees=0.0)
    assert np.all(np.isfinite(take.channels))
    boundary = segments[1][0]
    jump = np.abs(take.channels[boundary] - take.channels[boundary - 1]).max()
    typical = np.abs(np.diff(take.channels[:boundary - 1], axis=0)).max()
    assert jump > typical


def test_it_follows_a_given_plan_of_actions_and_lengths():
    take, segments = synth.generate(seed=1, fps=60.0, plan=[("idle", 6.0), ("kick", 1.8),
                                                             ("walk", 6.0)])
    assert segments == [(0, 360, "idle"), (360, 468, "kick"), (468, 828, "walk")]
    assert take.n_frames == 828


@pytest.mark.parametrize("plan, fault", [
    ([("idle", 6.0), ("dance", 2.0)], r"plan\[1\]: unknown action 'dance'"),
    ([("idle", 0.3)], r"plan\[0\]: idle must last longer than transition_seconds"),
    ([], "plan: no actions"),
])
def test_it_refuses_a_plan_it_cannot_follow(plan, fault):
    with pytest.raises(ValueError, match=fault):
        synth.generate(plan=plan)
