"""``python -m benchmarks.quality [--loo]`` and ``python -m benchmarks.quality speed io|adapt``."""

import sys

from benchmarks.quality.cli import main

sys.exit(main())
