"""Shared fixtures: the real CMU captures beside the repository, skipped when absent."""

from pathlib import Path

import pytest

from motionlib.shared_data import data_dir

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


def labelled_takes(kind: str = "skeleton", name: str | None = None) -> list:
    """The labelled takes of ``kind`` (``benchmarks.quality.data.discover``), only those called ``name``
    when given, not read; skipped when the shared data does not hold them."""
    from benchmarks.quality.data import discover

    takes = [t for t in discover()[0] if t.kind == kind and name in (None, t.name)]
    if not takes:
        pytest.skip(f"labelled CMU takes ({kind}{', ' + name if name else ''}) are not "
                    f"available (needs ../shared/data)")
    return takes


def skeleton_takes() -> list:
    """The full-skeleton labelled takes with their motion, read."""
    return [(t, t.read()) for t in labelled_takes()]
