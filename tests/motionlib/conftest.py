"""Shared fixtures: the real CMU captures beside the repository, skipped when absent."""

from pathlib import Path

import pytest

from motionlib.benchdata import data_dir

DATA = data_dir()
CMU = DATA / "cmu"


def cmu_file(*parts: str) -> Path:
    path = CMU.joinpath(*parts)
    if not path.is_file():
        pytest.skip(f"real CMU capture {path} is not available (needs ../shared/data)")
    return path


@pytest.fixture
def bvh_13_29() -> Path:
    return cmu_file("bvh", "13_29.bvh")


@pytest.fixture
def amc_13_29() -> tuple[Path, Path]:
    return cmu_file("amc", "13_29.amc"), cmu_file("asf", "13.asf")


def skeleton_takes() -> list:
    """The full-skeleton labelled takes (``benchdata.discover``), read; skipped when the
    shared data is absent."""
    from motionlib.benchdata import discover

    takes = [t for t in discover()[0] if t.kind == "skeleton"]
    if not takes:
        pytest.skip("labelled CMU takes are not available (needs ../shared/data)")
    return [(t, t.read()) for t in takes]
