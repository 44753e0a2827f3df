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
