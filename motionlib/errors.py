"""Domain errors of motionlib, all under :class:`MotionlibError` (a ``ValueError``).

- :class:`CaptureError`: a capture file (or a take built from one) cannot be used; its message
  names the file, the line and what was wrong, e.g. ``13_29.bvh:190: expected 96 values, found 95``;
- :class:`ParamError`: a segmenter name or parameter value is invalid;
- :class:`InputError`: any other argument a caller passed that cannot be used (a frame range,
  a tolerance, arrays of the wrong shape), naming the argument and its value.

A ``ValueError`` that is not a ``MotionlibError`` (numpy's, say) is a bug, not the caller's
fault: the service reports it as an internal error.
"""

from __future__ import annotations

import os

MAX_MESSAGE = 1000


def shorten(value, limit: int = 40) -> str:
    """``repr(value)`` cut to about ``limit`` characters, for naming a value in a message
    (a 1 MB joint name must not be echoed back whole)."""
    text = str(value)
    return repr(text) if len(text) <= limit else repr(text[:limit]) + f"... ({len(text)} characters)"


class MotionlibError(ValueError):
    """Base of every error motionlib raises on purpose."""


class InputError(MotionlibError):
    """An argument that cannot be used; the message names it and its value."""


class ParamError(MotionlibError):
    """A segmenter name or parameter value is invalid; the message names it."""


class CaptureError(MotionlibError):
    """A capture file (or a take built from one) cannot be used as it is.

    Parameters
    ----------
    message : str
        What was wrong, naming the offending value.
    path : str or os.PathLike, optional
        The file at fault; shown by its name.
    line : int, optional
        1-based line number in that file.
    """

    def __init__(self, message: str, *, path: str | os.PathLike | None = None,
                 line: int | None = None):
        # Values are shortened where they are named; this is the net under all of them.
        self.reason = message if len(message) <= MAX_MESSAGE else message[:MAX_MESSAGE] + "..."
        self.path = None if path is None else os.fspath(path)
        self.line = line
        super().__init__(self._format())

    def _format(self) -> str:
        if self.path is None:
            return self.reason
        where = os.path.basename(self.path) or self.path
        if self.line is not None:
            where = f"{where}:{self.line}"
        return f"{where}: {self.reason}"
