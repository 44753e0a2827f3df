"""Times as annotation files write them, turned into a take's frames and back.

- frames: a whole number, ``"120"``;
- seconds: a decimal number, ``"1.5"``, or with an ``s``: ``"2s"``;
- SMPTE timecode ``HH:MM:SS:FF`` (``MM:SS:FF`` and ``SS:FF`` too) at the take's rate rounded
  to whole frames, non-drop-frame (a 29.97 fps take counts 30 frames a second), as the
  review page shows it.

A time in seconds becomes the nearest frame boundary: ``round(seconds * fps)``.
"""

from __future__ import annotations

import math
import re

FRAME = re.compile(r"^[0-9]+$")
SECONDS = re.compile(r"^[0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?\s*s?$")
TIMECODE = re.compile(r"^[0-9]+(?::[0-9]+){1,3}$")


class TimeError(ValueError):
    """A cell that is no time of the expected form; the message says what it is not."""


def timecode_rate(fps: float) -> int:
    """Whole frames of one timecode second."""
    return max(1, round(fps))


def frames_of(cell: str, form: str, fps: float) -> int:
    """The frame that ``cell`` names in ``form``: "frame", "seconds", "timecode", or "any"
    (a whole number is frames, a decimal number or ``…s`` seconds, ``a:b:c`` timecode)."""
    text = cell.strip()
    if form == "any":
        form = ("frame" if FRAME.match(text) else "timecode" if TIMECODE.match(text)
                else "seconds")
    if form == "frame":
        if not FRAME.match(text):
            raise TimeError(f"{text!r} is not a whole frame number")
        return int(text)
    if form == "timecode":
        return timecode_frames(text, fps)
    if not SECONDS.match(text):
        raise TimeError(f"{text!r} is not a time in seconds, a frame number or a timecode")
    return seconds_frames(float(text.rstrip("sS ")), fps)


def seconds_frames(seconds: float, fps: float) -> int:
    value = seconds * fps
    if not math.isfinite(value) or abs(value) > 2**53:
        raise TimeError(f"{seconds!r} seconds is not a time of a take")
    return round(value)


def timecode_frames(text: str, fps: float) -> int:
    if not TIMECODE.match(text):
        raise TimeError(f"{text!r} is not a timecode HH:MM:SS:FF")
    rate = timecode_rate(fps)
    ff, ss, mm, hh = ([int(p) for p in reversed(text.split(":"))] + [0, 0])[:4]
    if ff >= rate:
        raise TimeError(f"{text}: frames must be below {rate} at {fps:g} fps, not {ff}")
    if ss >= 60 or mm >= 60:
        raise TimeError(f"{text}: seconds and minutes must be below 60")
    return ((hh * 60 + mm) * 60 + ss) * rate + ff


def timecode(frame: int, fps: float) -> str:
    """``HH:MM:SS:FF`` of a frame at the take's rate (the inverse of :func:`timecode_frames`)."""
    rate = timecode_rate(fps)
    width = max(2, len(str(rate - 1)))
    seconds, ff = divmod(frame, rate)
    return f"{seconds // 3600:02d}:{seconds // 60 % 60:02d}:{seconds % 60:02d}:{ff:0{width}d}"


def seconds(frame: int, fps: float) -> float:
    """The time of a frame boundary in seconds, rounded to the microsecond."""
    return round(frame / fps, 6)
