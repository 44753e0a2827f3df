"""Command-line arguments shared by several ``python -m motionlib`` commands, and how a
command line runs (``run``), which the benchmarks' command line shares.

A module of its own so that the package's parser and the command modules it registers
both import it, and no command module imports the parser back.
"""

from __future__ import annotations

import sys

from motionlib.errors import CaptureError

# The exit status of a command given something it cannot use (a bad file, value or path).
EXIT_USAGE = 2


def run(parser, argv: list[str] | None, name: str) -> int:
    """Parse ``argv`` with ``parser`` and run the chosen command's ``handler``; return the
    exit status. An error a user can fix prints one line naming ``name`` and the command,
    and gives ``EXIT_USAGE``."""
    args = parser.parse_args(argv)
    try:
        return args.handler(args)
    except (CaptureError, ValueError, OSError) as exc:
        message = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        print(f"{name} {args.command}: error: {message}", file=sys.stderr)
        return EXIT_USAGE


def add_animation(p) -> None:
    p.add_argument("--animation", help="which animation of an FBX file with several (its name "
                                       "or 0-based number; default: the first)")


def animation_arg(value: str | None) -> str | int | None:
    """``--animation``: a number picks by position, anything else by name."""
    return int(value) if value is not None and value.isdigit() else value
