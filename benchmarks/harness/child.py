"""The process a benchmark runs in: ``python -m benchmarks.harness.child NAME ARGS...``
imports NAME's module and calls its ``main()`` with ``ARGS`` as its command line.

The runner starts it, in this checkout or with a worktree's product first on the import
path (``against``); nobody types it.
"""

import importlib
import sys

from benchmarks.registry import BENCHMARKS


def main() -> int:
    name, args = sys.argv[1], sys.argv[2:]
    sys.argv = [f"python -m benchmarks {name}", *args]  # what argparse shows as the program
    status = importlib.import_module(BENCHMARKS[name].module).main()
    return status if isinstance(status, int) else 0


if __name__ == "__main__":
    sys.exit(main())
