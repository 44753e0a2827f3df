"""Seeded synthetic takes with known action boundaries and labels.

A take is a sequence of actions (walk in place, jumping jack, squat, punch, arm circles, kick,
idle) on a CMU-like skeleton (cgspeed joint names, CMU proportions, Y up, facing +Z). Each action
is a periodic pattern of joint angles with its own period, amplitude and phase drawn per
segment; consecutive segments differ, are cross-faded over a short transition, and carry a slow
drift plus small jitter so no two frames repeat exactly. The true boundary is the middle of each
transition. Used by tests, segmenter tests and the service demo.

Example
-------
>>> take, segments = generate(seed=3, duration=60.0)
>>> take.n_frames, len(segments), segments[0]
(7200, 10, (0, 594, 'arm_circles'))

The skeleton starts facing a random heading; its rest pose is a T-pose with zero channels, but
generated takes always stand with the arms down, so ``rest_pose_frame`` is None.
"""

from __future__ import annotations

import numpy as np

from motionlib.errors import InputError
from motionlib.skeleton import Skeleton
from motionlib.take import Take

ACTIONS = ("idle", "walk", "jumping_jack", "squat", "punch", "arm_circles", "kick")

# (name, parent, offset) in CMU length units (cgspeed naming, thorax length dropped as there).
_JOINTS = [
    ("Hips", None, (0, 0, 0)),
    ("LeftUpLeg", "Hips", (1.6, -1.6, 0.3)), ("LeftLeg", "LeftUpLeg", (0, -7.6, 0)),
    ("LeftFoot", "LeftLeg", (0, -7.9, 0)), ("LeftToeBase", "LeftFoot", (0, -0.6, 2.2)),
    ("RightUpLeg", "Hips", (-1.6, -1.6, 0.3)), ("RightLeg", "RightUpLeg", (0, -7.6, 0)),
    ("RightFoot", "RightLeg", (0, -7.9, 0)), ("RightToeBase", "RightFoot", (0, -0.6, 2.2)),
    ("LowerBack", "Hips", (0, 0, 0)), ("Spine", "LowerBack", (0, 2.0, -0.2)),
    ("Spine1", "Spine", (0, 2.0, 0)), ("Neck", "Spine1", (0, 0, 0)),
    ("Neck1", "Neck", (0, 1.8, 0.1)), ("Head", "Neck1", (0, 1.8, -0.1)),
    ("LeftShoulder", "Spine1", (0, 0, 0)), ("LeftArm", "LeftShoulder", (3.5, 1.2, -0.3)),
    ("LeftForeArm", "LeftArm", (5.4, 0, 0)), ("LeftHand", "LeftForeArm", (3.7, 0, 0)),
    ("RightShoulder", "Spine1", (0, 0, 0)), ("RightArm", "RightShoulder", (-3.5, 1.2, -0.3)),
    ("RightForeArm", "RightArm", (-5.4, 0, 0)), ("RightHand", "RightForeArm", (-3.7, 0, 0)),
]
_END_SITES = {"LeftToeBase": (0, 0, 1.2), "RightToeBase": (0, 0, 1.2), "Head": (0, 1.8, 0),
              "LeftHand": (1.8, 0, 0), "RightHand": (-1.8, 0, 0)}
_ROOT = ("Xposition", "Yposition", "Zposition", "Zrotation", "Yrotation", "Xrotation")
_JOINT = ("Zrotation", "Yrotation", "Xrotation")
STANDING_HEIGHT = 17.7  # root height with straight legs, feet on Y = 0
_LEG = (7.6, 7.9)  # thigh and shin lengths


def skeleton() -> Skeleton:
    """The synthetic CMU-like skeleton (23 joints, root 6 channels, others ZYX)."""
    names = [name for name, _, _ in _JOINTS]
    return Skeleton(
        names=names,
        parents=[-1 if p is None else names.index(p) for _, p, _ in _JOINTS],
        offsets=[o for _, _, o in _JOINTS],
        channels=[_ROOT] + [_JOINT] * (len(names) - 1),
        rotation_orders=["ZYX"] * len(names),
        end_sites={names.index(n): np.array(o, float) for n, o in _END_SITES.items()})


def _rest(n: int) -> dict[str, np.ndarray]:
    """Standing, arms hanging: the base every action adds to (angles in degrees)."""
    return {"Hips.Yposition": np.full(n, STANDING_HEIGHT),
            "LeftArm.Zrotation": np.full(n, -75.0), "RightArm.Zrotation": np.full(n, 75.0)}


# Each action maps phase (radians, shape (n,)) and an amplitude factor to angle offsets from
# the rest pose. Arms: Z lifts sideways (left -, right +), Y swings forward (left -, right +);
# legs: X negative flexes the hip forward, LeftLeg/RightLeg X positive bends the knee.
def _idle(ph, a):
    return {"Hips.Yrotation": 3 * a * np.sin(ph), "Spine.Xrotation": 2 * a * np.sin(2 * ph),
            "LeftArm.Yrotation": -3 * a * np.sin(ph), "RightArm.Yrotation": 3 * a * np.sin(ph)}


def _walk(ph, a):
    up_l, up_r = np.maximum(np.sin(ph), 0), np.maximum(-np.sin(ph), 0)
    return {"LeftUpLeg.Xrotation": -45 * a * up_l, "LeftLeg.Xrotation": 70 * a * up_l,
            "RightUpLeg.Xrotation": -45 * a * up_r, "RightLeg.Xrotation": 70 * a * up_r,
            "LeftArm.Yrotation": 30 * a * np.sin(ph), "RightArm.Yrotation": 30 * a * np.sin(ph),
            "Hips.Yposition": 0.4 * a * np.abs(np.sin(ph))}


def _jumping_jack(ph, a):
    s = (1 - np.cos(ph)) / 2
    return {"LeftArm.Zrotation": 150 * a * s, "RightArm.Zrotation": -150 * a * s,
            "LeftUpLeg.Zrotation": 15 * a * s, "RightUpLeg.Zrotation": -15 * a * s,
            "Hips.Yposition": 1.5 * a * np.abs(np.sin(ph))}


def _squat(ph, a):
    s = a * (1 - np.cos(ph)) / 2
    hip, knee = 80 * s, 120 * s
    # Keep the ankles where they stand: drop and shift the hips by what the bent legs lose.
    thigh, shin = _LEG
    drop = thigh + shin - thigh * np.cos(np.radians(hip)) - shin * np.cos(np.radians(knee - hip))
    ahead = thigh * np.sin(np.radians(hip)) - shin * np.sin(np.radians(knee - hip))
    return {"LeftUpLeg.Xrotation": -hip, "RightUpLeg.Xrotation": -hip,
            "LeftLeg.Xrotation": knee, "RightLeg.Xrotation": knee,
            "LeftFoot.Xrotation": hip - knee, "RightFoot.Xrotation": hip - knee,
            "Spine.Xrotation": 25 * s, "Hips.Yposition": -drop, "Hips.Zposition": -ahead,
            "LeftArm.Yrotation": -85 * s, "RightArm.Yrotation": 85 * s}


def _punch(ph, a):
    pl, pr = np.maximum(np.sin(ph), 0) ** 2 * a, np.maximum(-np.sin(ph), 0) ** 2 * a
    return {"LeftArm.Zrotation": 10 + 60 * pl, "RightArm.Zrotation": -10 - 60 * pr,
            "LeftArm.Yrotation": -40 - 45 * pl, "RightArm.Yrotation": 40 + 45 * pr,
            "LeftForeArm.Yrotation": -110 * (1 - pl), "RightForeArm.Yrotation": 110 * (1 - pr),
            "Spine.Yrotation": 15 * (pl - pr), "LeftLeg.Xrotation": 12 + 0 * ph,
            "RightLeg.Xrotation": 12 + 0 * ph, "Hips.Yposition": -0.3 + 0 * ph}


def _arm_circles(ph, a):
    return {"LeftArm.Zrotation": 75 + 20 * a * np.cos(ph), "LeftArm.Yrotation": 20 * a * np.sin(ph),
            "RightArm.Zrotation": -75 - 20 * a * np.cos(ph),
            "RightArm.Yrotation": -20 * a * np.sin(ph)}


def _kick(ph, a):
    kl, kr = np.maximum(np.sin(ph), 0) * a, np.maximum(-np.sin(ph), 0) * a
    return {"LeftUpLeg.Xrotation": -75 * kl, "RightUpLeg.Xrotation": -75 * kr,
            "LeftLeg.Xrotation": 40 * np.sin(2 * ph) ** 2 * a + 5,
            "RightLeg.Xrotation": 40 * np.sin(2 * ph) ** 2 * a + 5,
            "LeftArm.Zrotation": 30 + 0 * ph, "RightArm.Zrotation": -30 + 0 * ph,
            "Spine.Xrotation": -10 * (kl + kr)}


_PATTERNS = {"idle": (_idle, 4.0), "walk": (_walk, 1.1), "jumping_jack": (_jumping_jack, 1.0),
             "squat": (_squat, 2.4), "punch": (_punch, 0.9), "arm_circles": (_arm_circles, 0.8),
             "kick": (_kick, 1.6)}


def _plan(rng, fps, duration, n_segments, actions, segment_seconds):
    """Segment lengths in frames and labels; consecutive labels differ."""
    lo, hi = segment_seconds
    labels, lengths = [], []
    total, target = 0, None if duration is None else int(round(duration * fps))
    while (len(lengths) < n_segments) if target is None else (total < target):
        choices = [a for a in actions if not labels or a != labels[-1]]
        labels.append(str(rng.choice(choices)))
        lengths.append(int(round(rng.uniform(lo, hi) * fps)))
        total += lengths[-1]
    if target is not None:
        lengths[-1] -= total - target
        if len(lengths) > 1 and lengths[-1] < lo * fps / 2:  # too short to be an action
            tail = lengths.pop()
            lengths[-1] += tail
            labels.pop()
    return lengths, labels


def _segment_angles(rng, label, t, n):
    pattern, period = _PATTERNS[label]
    period *= rng.uniform(0.85, 1.15)
    phase = 2 * np.pi * t / period + rng.uniform(0, 2 * np.pi)
    return pattern(phase, rng.uniform(0.85, 1.15))


def _add_actions(channels, column, rng, labels, bounds, t, half):
    """Add each segment's action, faded in and out over ``half`` frames either side of its
    bounds (the fades of neighbours sum to one)."""
    n = len(channels)
    for i, label in enumerate(labels):
        lo, hi = max(0, int(bounds[i] - half)), min(n, int(np.ceil(bounds[i + 1] + half)))
        frames = np.arange(lo, hi)
        weight = np.ones(hi - lo)
        if i > 0:
            weight *= _ramp(frames, bounds[i], half)
        if i < len(labels) - 1:
            weight *= 1 - _ramp(frames, bounds[i + 1], half)
        for key, values in _segment_angles(rng, label, t[lo:hi], hi - lo).items():
            channels[lo:hi, column[key]] += weight * values


def _ramp(frames, boundary, half):
    """0 before ``boundary - half``, 1 after ``boundary + half``, smooth in between."""
    if half <= 0:
        return (frames >= boundary).astype(float)
    return _smoothstep((frames - boundary + half) / (2 * half))


def _smoothstep(x):
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3 - 2 * x)


def generate(seed: int = 0, fps: float = 120.0, *, duration: float | None = None,
             n_segments: int = 6, actions=ACTIONS, segment_seconds=(4.0, 8.0),
             transition_seconds: float = 0.5, noise_degrees: float = 0.3, plan=None):
    """Generate a synthetic take of known actions.

    Parameters
    ----------
    seed : int
        Same seed, same take.
    fps : float
        Frame rate in Hz.
    duration : float, optional
        Length in seconds; when given, segments are drawn until it is filled and
        ``n_segments`` is ignored.
    n_segments : int
        Number of actions when ``duration`` is None.
    actions : sequence of str
        Labels to draw from, a subset of :data:`ACTIONS` with at least two entries.
    segment_seconds : (float, float)
        Range of a segment's length in seconds.
    transition_seconds : float
        Cross-fade length around each boundary.
    noise_degrees : float
        Amplitude of the slow drift and jitter added to every angle.
    plan : sequence of (str, float), optional
        The take's actions and their lengths in seconds, in order, instead of drawn ones
        (``duration``, ``n_segments``, ``actions`` and ``segment_seconds`` are then unused).

    Returns
    -------
    take : Take
        ``format == "bvh"``, ``frame_time == 1 / fps``, name ``"synth-<seed>"``.
    segments : list of (start, stop, label)
        0-based frames, ``stop`` exclusive, covering ``[0, n_frames)``; a boundary is the
        middle of its transition.
    """
    rng = np.random.default_rng(seed)
    if plan is None:
        _check(fps, duration, n_segments, actions, segment_seconds, transition_seconds)
        lengths, labels = _plan(rng, fps, duration, n_segments, list(actions), segment_seconds)
    else:
        labels, lengths = _check_plan(plan, fps, transition_seconds)
    bounds = np.concatenate([[0], np.cumsum(lengths)])
    n = int(bounds[-1])
    sk = skeleton()
    column = {f"{sk.names[j]}.{c}": s + k for j, (s, chans) in
              enumerate(zip(sk.channel_starts, sk.channels, strict=True))
              for k, c in enumerate(chans)}
    t = np.arange(n) / fps
    channels = np.zeros((n, sk.n_channels))
    for key, values in _rest(n).items():
        channels[:, column[key]] = values
    _add_actions(channels, column, rng, labels, bounds, t, transition_seconds * fps / 2)
    channels += _noise(rng, t, sk.n_channels, noise_degrees)
    _face(channels, column, rng.uniform(-180, 180))
    segments = [(int(bounds[i]), int(bounds[i + 1]), labels[i]) for i in range(len(labels))]
    take = Take(name=f"synth-{seed}", format="bvh", fps=float(fps), frame_time=1.0 / fps,
                channels=channels, skeleton=sk, rest_pose_frame=None)
    return take, segments


def _face(channels, column, heading_deg):
    """Turn the whole take about the vertical axis: root yaw and root horizontal motion."""
    h = np.radians(heading_deg)
    x, z = channels[:, column["Hips.Xposition"]].copy(), channels[:, column["Hips.Zposition"]]
    channels[:, column["Hips.Xposition"]] = x * np.cos(h) + z * np.sin(h)
    channels[:, column["Hips.Zposition"]] = z * np.cos(h) - x * np.sin(h)
    channels[:, column["Hips.Yrotation"]] += heading_deg


def _noise(rng, t, n_channels, amplitude):
    """Slow drift plus small jitter, shape (n_frames, n_channels).

    The drift mixes 8 shared sinusoids (0.05-0.5 Hz) with random weights per channel: one
    matmul instead of a sine per channel and frame, which kept long takes slow.
    """
    freq = rng.uniform(0.05, 0.5, size=8)
    arg = 2 * np.pi * t[:, None] * freq
    waves = np.hstack([np.sin(arg), np.cos(arg)])
    weights = rng.standard_normal((16, n_channels)) / 4
    jitter = rng.standard_normal((t.size, n_channels), dtype=np.float32)
    return amplitude * (waves @ weights + 0.1 * jitter)


def _check_plan(plan, fps, transition_seconds) -> tuple[list[str], list[int]]:
    """Labels and lengths in frames of a given plan; InputError naming a bad entry."""
    if not fps > 0:
        raise InputError(f"fps must be positive, got {fps}")
    labels, lengths = [], []
    for i, (label, seconds) in enumerate(plan):
        if label not in ACTIONS:
            raise InputError(f"plan[{i}]: unknown action {label!r} (one of {', '.join(ACTIONS)})")
        if not seconds > transition_seconds:
            raise InputError(f"plan[{i}]: {label} must last longer than transition_seconds "
                             f"({transition_seconds}), got {seconds}")
        labels.append(str(label))
        lengths.append(int(round(seconds * fps)))
    if not labels:
        raise InputError("plan: no actions")
    return labels, lengths


def _check(fps, duration, n_segments, actions, segment_seconds, transition_seconds):
    if not fps > 0:
        raise InputError(f"fps must be positive, got {fps}")
    if duration is not None and not duration > 0:
        raise InputError(f"duration must be positive seconds, got {duration}")
    if duration is None and n_segments < 1:
        raise InputError(f"n_segments must be at least 1, got {n_segments}")
    unknown = sorted(set(actions) - set(ACTIONS))
    if unknown or len(set(actions)) < 2:
        raise InputError(f"actions must be at least two of {', '.join(ACTIONS)}; got "
                         f"{', '.join(map(str, actions))}")
    lo, hi = segment_seconds
    if not 0 < lo <= hi:
        raise InputError(f"segment_seconds must be (min, max) with 0 < min <= max, got "
                         f"{segment_seconds}")
    if not 0 <= transition_seconds < lo:
        raise InputError(f"transition_seconds must be in [0, {lo}) (shorter than a segment), "
                         f"got {transition_seconds}")
