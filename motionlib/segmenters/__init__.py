"""Registry of segmentation methods: one name -> one Segmenter class.

The service and the command line both list methods and validate parameters here, so
they always agree on names and parameter schemas.
"""

from __future__ import annotations

from motionlib.segmenters.base import Param, ParamError, Segmentation, Segmenter
from motionlib.segmenters.bone_angle import BoneAngle
from motionlib.segmenters.default import Default
from motionlib.segmenters.joint_distance_pca import JointDistancePCA
from motionlib.segmenters.ppca import PPCA

_REGISTRY: dict[str, type[Segmenter]] = {cls.name: cls for cls in (Default, BoneAngle, JointDistancePCA, PPCA)}

__all__ = [
    "Param",
    "ParamError",
    "Segmentation",
    "Segmenter",
    "get_segmenter",
    "list_segmenters",
    "parse_param_args",
]


def list_segmenters() -> list[type[Segmenter]]:
    """Every registered method, the service's default first."""
    return sorted(_REGISTRY.values(), key=lambda cls: (cls.name != "default", cls.name))


def parse_param_args(pairs: list[str] | None) -> dict[str, str]:
    """``["k=v", ...]`` from the command line -> ``{"k": "v"}`` (values still strings)."""
    params: dict[str, str] = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key.strip():
            raise ParamError(f"--param: expected NAME=VALUE, got {pair!r}")
        params[key.strip()] = value.strip()
    return params


def get_segmenter(name: str) -> type[Segmenter]:
    """The Segmenter class registered under ``name``; ParamError if there is none."""
    try:
        return _REGISTRY[name]
    except (KeyError, TypeError):
        valid = ", ".join(cls.name for cls in list_segmenters())
        raise ParamError(f"method: unknown segmenter {name!r} (valid: {valid})") from None
