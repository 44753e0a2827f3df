"""The real point takes under ``../shared/data/points`` (README there), skipped when absent."""

import os
from pathlib import Path

import pytest

DATA = Path(os.environ.get("CUTROOM_BENCH_DATA",
                           Path(__file__).resolve().parents[2] / ".." / "shared" / "data"))
POINTS = DATA.resolve() / "points"


def points_file(*parts: str) -> Path:
    path = POINTS.joinpath(*parts)
    if not path.is_file():
        pytest.skip(f"real point take {path} is not available (needs ../shared/data)")
    return path


HDM05 = ("hdm05", "HDM_bd_05-01_01_120.c3d")
