"""Real labelled takes made into harder cases for the quality benchmark: activities cut
short (in the middle, throughout, at the ends of the take) and the take played slower or
quicker, with the true cuts moved with the motion.

Each works on any take with ``channels`` (a ``motionlib.Take`` or a four-channel
``data.ChannelTake``) and returns a take of the same type, so what the detector sees is
still real motion: the performer's own entries into and exits from each activity.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from motionlib.errors import InputError


def shortened(take, truth: np.ndarray, activity: int, seconds: float):
    """``take`` with its inner activity ``activity`` (between true cuts ``activity`` and
    ``activity + 1``) cut down to ``seconds`` by removing its middle: real motion holding a
    real short activity, its entry and exit as the performer made them.

    Returns
    -------
    (take, truth) : the shorter take (same type, ``positions`` dropped) and its true cuts,
        those after the activity moved back by the frames removed; the two windows beside
        it clipped at the join, so that no window reaches into the removed frames. None
        when the activity (between the best estimates) is not longer than ``seconds``.
    """
    truth = np.asarray(truth, dtype=np.int64)
    if not 0 <= activity < len(truth) - 1:
        raise InputError(f"activity {activity}: a take with {len(truth)} cuts has inner "
                         f"activities 0 to {len(truth) - 2}")
    keep = int(round(seconds * take.fps))
    start, stop = int(truth[activity, 1]), int(truth[activity + 1, 1])
    if stop - start <= keep:
        return None
    join, resume = start + keep // 2, stop - (keep - keep // 2)
    channels = np.concatenate([take.channels[:join], take.channels[resume:]])
    out = truth.copy()
    out[activity + 1:] -= resume - join
    out[activity, 2] = min(out[activity, 2], join - 1)
    out[activity + 1, 0] = max(out[activity + 1, 0], join)
    return with_channels(take, channels), out


def shortened_throughout(take, truth: np.ndarray, seconds: float):
    """``take`` with every inner activity longer than ``seconds`` cut down to ``seconds``
    (``shortened``, last first): real motion made of short activities throughout.

    Returns (take, truth) as ``shortened``; the take itself when no activity is longer.
    """
    truth = np.asarray(truth, dtype=np.int64)
    for activity in range(len(truth) - 2, -1, -1):
        cut = shortened(take, truth, activity, seconds)
        if cut is not None:
            take, truth = cut
    return take, truth


def played_at(take, truth: np.ndarray, speed: float):
    """``take`` as if performed ``speed`` times as fast (0.8: 25 % longer), its channels
    resampled linearly (angles through their shortest turn; no channel moves by half a
    turn, 180 units, between two frames, so positions pass unchanged), and its true cuts
    moved with the motion: the same take by a slower or quicker performer.

    Returns (take, truth) as ``shortened``.
    """
    if not speed > 0:
        raise InputError(f"speed: must be above 0, got {speed}")
    channels = np.asarray(take.channels, dtype=float)
    n = len(channels)
    source = np.linspace(0, n - 1, max(2, int(round(n / speed))))
    turned = np.unwrap(channels, period=360.0, axis=0)
    resampled = np.stack([np.interp(source, np.arange(n), turned[:, j])
                          for j in range(channels.shape[1])], axis=1)
    moved = np.round(np.asarray(truth, dtype=float) / speed).astype(np.int64)
    return with_channels(take, resampled), moved


def with_channels(take, channels: np.ndarray):
    """``take`` (same type) with other channel rows; cached positions dropped."""
    changes = {"channels": channels}
    if hasattr(take, "positions"):
        changes["positions"] = None
    return replace(take, **changes)


def trimmed(take, truth: np.ndarray, side: str, seconds: float):
    """``take`` with its first (``side`` "first") or last ("last") activity cut down to
    ``seconds`` by dropping frames at that end of the take: real motion whose take starts
    or ends with a short activity.

    Returns
    -------
    (take, truth) : the shorter take (same type, ``positions`` dropped) and its true cuts
        (moved back by the frames dropped at the start), the windows clipped to the take;
        None when that activity (to or from the best estimate) is not longer than
        ``seconds``.
    """
    truth = np.asarray(truth, dtype=np.int64)
    if side not in ("first", "last"):
        raise InputError(f"side: expected 'first' or 'last', got {side!r}")
    if len(truth) == 0:
        raise InputError("a take with no cuts has no first or last activity to trim")
    keep = int(round(seconds * take.fps))
    start, stop = (int(truth[0, 1]) - keep, take.n_frames) if side == "first" else \
        (0, int(truth[-1, 1]) + keep)
    if (start if side == "first" else take.n_frames - stop) <= 0:
        return None
    out = np.clip(truth - start, 0, stop - start - 1)
    return with_channels(take, np.array(take.channels[start:stop])), out
