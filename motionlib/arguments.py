"""Command-line arguments shared by several ``python -m motionlib`` commands.

A module of its own so that ``motionlib.cli`` and the commands it registers from other
packages (``segmenters.command``) both import it, and neither imports the other back.
"""

from __future__ import annotations


def add_animation(p) -> None:
    p.add_argument("--animation", help="which animation of an FBX file with several (its name "
                                       "or 0-based number; default: the first)")


def animation_arg(value: str | None) -> str | int | None:
    """``--animation``: a number picks by position, anything else by name."""
    return int(value) if value is not None and value.isdigit() else value
