"""Where the shared data lives: the real CMU takes and their labels beside the repository.

The demo (``manage.py demo``), the tests and the benchmarks find the folder the same way,
through :func:`data_dir`. It lives in the service because the demo is part of it and must
not need the benchmark apparatus; it imports nothing else (no Django), so the library's
tests and benchmarks import it without starting the service. What the folder holds and how
its labelled takes are read is the benchmark's business (``benchmarks.quality.data``).
"""

from __future__ import annotations

import os
from pathlib import Path

DEFAULT_DATA_DIR = Path(__file__).resolve().parents[1] / ".." / "shared" / "data"


def data_dir() -> Path:
    """The shared data folder: ``$CUTROOM_BENCH_DATA`` if set, else ``shared/data`` beside
    the repository. It may not exist; callers say so or skip."""
    return Path(os.environ.get("CUTROOM_BENCH_DATA", DEFAULT_DATA_DIR)).resolve()
