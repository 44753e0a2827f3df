"""Segmenter base class, parameter schema and result type.

A segmenter is configured by keyword parameters that ``__init__`` only stores
(scikit-learn convention); ``fit`` validates them, computes the feature signal(s)
and the candidate cuts; ``predict`` returns them.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np

from motionlib.errors import ParamError

_TRUE = {"true", "1", "yes", "on"}
_FALSE = {"false", "0", "no", "off"}


@dataclass(frozen=True)
class Param:
    """One tunable parameter: type ("float", "int" or "bool"), default and bounds."""

    type: str
    default: Any
    min: float | None = None
    max: float | None = None
    description: str = ""

    def coerce(self, name: str, value: Any) -> Any:
        """Return ``value`` converted to this parameter's type, or raise ParamError."""
        if self.type == "bool":
            return _coerce_bool(name, value)
        number = _coerce_number(name, value, integer=self.type == "int")
        if (self.min is not None and number < self.min) or (
            self.max is not None and number > self.max
        ):
            raise ParamError(f"{name}: must be {self._range_text()}, got {value!r}")
        return number

    def _range_text(self) -> str:
        if self.min is not None and self.max is not None:
            return f"between {self.min:g} and {self.max:g}"
        if self.min is not None:
            return f"at least {self.min:g}"
        return f"at most {self.max:g}"

    def as_dict(self) -> dict[str, Any]:
        return {
            "type": self.type,
            "default": self.default,
            "min": self.min,
            "max": self.max,
            "description": self.description,
        }


def _coerce_bool(name: str, value: Any) -> bool:
    if isinstance(value, bool | np.bool_):
        return bool(value)
    if isinstance(value, str) and value.strip().lower() in _TRUE | _FALSE:
        return value.strip().lower() in _TRUE
    if isinstance(value, int | np.integer) and value in (0, 1):
        return bool(value)
    raise ParamError(f"{name}: must be true or false, got {value!r}")


def _coerce_number(name: str, value: Any, *, integer: bool) -> float | int:
    kind = "an integer" if integer else "a number"
    if isinstance(value, bool | np.bool_):
        raise ParamError(f"{name}: must be {kind}, got {value!r}")
    try:
        number = float(value.strip()) if isinstance(value, str) else float(value)
    except (TypeError, ValueError):
        raise ParamError(f"{name}: must be {kind}, got {value!r}") from None
    if not np.isfinite(number):
        raise ParamError(f"{name}: must be a finite number, got {value!r}")
    if integer:
        if number != int(number):
            raise ParamError(f"{name}: must be an integer, got {value!r}")
        return int(number)
    return number


@dataclass
class Segmentation:
    """Candidate cuts of one take.

    cuts : (n_cuts,) int, 0-based take frames, sorted, 0 < c < n_frames; a cut c
        means a new segment starts at frame c.
    confidence : (n_cuts,) float in [0, 1].
    signals : name -> (n_frames,) float, the 1-D signal(s) the method used.
    timings : step name -> seconds.
    """

    cuts: np.ndarray
    confidence: np.ndarray
    signals: dict[str, np.ndarray] = field(default_factory=dict)
    timings: dict[str, float] = field(default_factory=dict)

    def checked(self, n_frames: int) -> Segmentation:
        """This result held to the contract above for a take of ``n_frames`` (in place,
        and returned): cuts as sorted unique ints inside the take, each confidence clipped
        to [0, 1]; a cut outside the take, or a repeated one, is dropped with its
        confidence. RuntimeError when there are not as many confidences as cuts."""
        cuts = np.asarray(self.cuts, dtype=np.int64)
        confidence = np.clip(np.asarray(self.confidence, dtype=float), 0.0, 1.0)
        if cuts.shape != confidence.shape:
            raise RuntimeError("segmenter returned cuts and confidence of different lengths")
        keep = (cuts > 0) & (cuts < n_frames)
        cuts, confidence = cuts[keep], confidence[keep]
        order = np.argsort(cuts, kind="stable")
        cuts, confidence = cuts[order], confidence[order]
        first = np.ones(len(cuts), dtype=bool)
        first[1:] = np.diff(cuts) > 0
        self.cuts, self.confidence = cuts[first], confidence[first]
        return self


class Segmenter:
    """Base class: subclasses set the class attributes and implement ``_segment``."""

    name: ClassVar[str] = ""
    title: ClassVar[str] = ""
    description: ClassVar[str] = ""
    params: ClassVar[dict[str, Param]] = {}

    def __init__(self, **params: Any) -> None:
        self.param_values = dict(params)

    @classmethod
    def validate_params(cls, values: dict[str, Any] | None) -> dict[str, Any]:
        """Coerce ``values`` to the parameter schema and fill in the defaults.

        Raises ParamError naming the first unknown parameter or bad value.
        """
        values = dict(values or {})
        unknown = sorted(set(values) - set(cls.params))
        if unknown:
            valid = ", ".join(sorted(cls.params)) or "none"
            raise ParamError(
                f"{unknown[0]}: unknown parameter for method {cls.name!r} (valid: {valid})"
            )
        return {
            key: (spec.coerce(key, values[key]) if key in values else spec.default)
            for key, spec in cls.params.items()
        }

    @classmethod
    def schema(cls) -> dict[str, Any]:
        """JSON-ready description of the method and its parameters."""
        return {
            "name": cls.name,
            "title": cls.title,
            "description": cls.description,
            "params": {key: spec.as_dict() for key, spec in cls.params.items()},
        }

    def fit(self, take: Any) -> Segmenter:
        """Compute candidate cuts for ``take`` (a ``motionlib.read`` result)."""
        values = self.validate_params(self.param_values)
        from motionlib.points import segmenter_input

        take = segmenter_input(take, self.name)
        start = time.perf_counter()
        result = self._segment(take, **values)
        result.timings["total"] = time.perf_counter() - start
        self.result_ = result.checked(take.n_frames)
        return self

    def predict(self) -> Segmentation:
        if not hasattr(self, "result_"):
            raise RuntimeError(f"{type(self).__name__}.predict() called before fit()")
        return self.result_

    def fit_predict(self, take: Any) -> Segmentation:
        return self.fit(take).predict()

    def _segment(self, take: Any, **params: Any) -> Segmentation:
        raise NotImplementedError


def first_frame(take: Any) -> int:
    """The first frame of the performance: after the added T-pose frame of a cgspeed BVH
    (``take.rest_pose_frame``), else 0."""
    return 0 if take.rest_pose_frame is None else int(take.rest_pose_frame) + 1


def take_positions(take: Any) -> tuple[np.ndarray, dict[str, int], int]:
    """World joint positions of the frames a segmenter should look at.

    A cgspeed BVH starts with an added T-pose frame (``take.rest_pose_frame``); it is
    not part of the performance, so detection starts after it. ``take.positions`` are
    used when set (a service that has just computed them for storage), else computed.
    A point take gives the body parts its marker set defines
    (``markersets.body_joints``, gaps interpolated; CaptureError for an unknown set).

    Returns
    -------
    positions : (n_used, n_joints, 3) world positions of frames ``first ..``.
    joints : canonical joint name -> index.
    first : take frame index of ``positions[0]``.
    """
    import motionlib
    from motionlib import markersets
    from motionlib.points import is_point_take

    if is_point_take(take):  # body parts from the marker set, gaps closed (features only)
        positions, joints = markersets.body_joints(take)
        return positions, joints, 0
    first = first_frame(take)
    known = getattr(take, "positions", None)
    positions = (motionlib.forward_kinematics(take) if known is None else known)[first:]
    return positions, motionlib.canonical_indices(take), first


def full_length(signal: np.ndarray, first: int) -> np.ndarray:
    """Pad a signal computed on frames ``first ..`` back to the take's length."""
    signal = np.asarray(signal, dtype=float)
    if first == 0 or len(signal) == 0:
        return signal
    return np.concatenate([np.full(first, signal[0]), signal])
