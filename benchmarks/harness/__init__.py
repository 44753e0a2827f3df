"""What every benchmark shares: where the product under test is, the machine and its load
(``machine``), timing and tables (``timing``), results files (``record``), another revision
in a git worktree (``against``) and the service started for a benchmark (``service``).

A benchmark always measures the tree its process imports the product from. The runner
(``python -m benchmarks``) runs it on this checkout, and with ``--against REV`` once more
on a worktree of ``REV``: there ``CUTROOM_BENCH_TREE`` names the worktree and
``CUTROOM_BENCH_REVISION`` the revision, so that files a benchmark builds and keeps (its
scratch databases, ``OUT``) are the revision's own and never another's.
"""

import os
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1]
# The product's tree: this checkout, or the worktree of the revision compared against.
REPO = Path(os.environ.get("CUTROOM_BENCH_TREE") or PACKAGE.parent)
REVISION = os.environ.get("CUTROOM_BENCH_REVISION", "")
RESULTS = PACKAGE / "results"
# Kept between runs, git-ignored; a revision compared against keeps its own.
OUT = PACKAGE / "out" / (f"at-{REVISION}" if REVISION else "")


def kept_name(name: str) -> str:
    """``name`` of something a benchmark builds once and keeps (a database), made the
    revision's own when the run is on another revision."""
    return f"{name}_at_{REVISION}" if REVISION else name


def data_dir() -> Path:
    """The shared data folder: ``$CUTROOM_BENCH_DATA`` if set, else ``shared/data`` beside
    this checkout (the same rule as ``motionlib.shared_data``, kept here so a run against
    an older revision, whose product keeps that function elsewhere, finds the data too)."""
    default = PACKAGE.parent / ".." / "shared" / "data"
    return Path(os.environ.get("CUTROOM_BENCH_DATA", default)).resolve()
