"""Command line: ``python -m motionlib <command> …``.

Each command is one ``add_<command>(subparsers)`` function that declares its arguments and sets
``handler``; a handler takes the parsed arguments, prints its result and returns an exit code.
Adding a command is adding one such function to :data:`COMMANDS`. Errors a user can fix
(bad files, bad arguments) print one line on stderr and exit with status 2.

- ``capture``: ``info`` and ``convert``;
- ``segment``: ``segment`` (a method's cuts, or the learner's with ``--examples``), drawing
  with ``plot`` when asked;
- ``common``: the arguments several commands share and how a command line runs (``run``),
  which the benchmarks' command line shares.

The library never imports this package: it sits on top of ``io``, ``segmenters`` and
``adapt``.
"""

from __future__ import annotations

import argparse

from motionlib.cli.capture import add_convert, add_info
from motionlib.cli.common import EXIT_USAGE, run
from motionlib.cli.segment import add_segment

COMMANDS = [add_info, add_convert, add_segment]


class _Parser(argparse.ArgumentParser):
    """Usage errors in one line (``--help`` still shows the full usage)."""

    def error(self, message: str):
        self.exit(EXIT_USAGE, f"{self.prog}: error: {message} (see --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="python -m motionlib",
                     description="Motion-capture takes: inspect, convert, segment.")
    subparsers = parser.add_subparsers(dest="command", required=True, metavar="command")
    for add in COMMANDS:
        add(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    return run(build_parser(), argv, "motionlib")
