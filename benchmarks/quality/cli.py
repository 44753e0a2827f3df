"""Command line of the research apparatus, which the runner calls (``quality``,
``learning-curve``, ``speed-io``, ``speed-adapt`` in ``benchmarks/registry.py``): the
quality benchmark by default, ``speed`` for motionlib's speed tables. Errors a user can fix print one line on stderr, exit status 2."""

from __future__ import annotations

import argparse

from benchmarks.quality import bench
from benchmarks.quality.speed import add_speed
from motionlib.cli.common import run


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m benchmarks quality",
        description="Every segmenter (default parameters) and two change-point peers on "
                    "every labelled take (rotation sets, then the point sets): a table per take and the mean. `speed` measures "
                    "how fast motionlib reads and detects instead.")
    parser.add_argument("--data", help="benchmark data folder (default: $CUTROOM_BENCH_DATA "
                                       "or ../shared/data)")
    parser.add_argument("--method", action="append", help="only this row (repeatable)")
    parser.add_argument("--loo", action="store_true",
                        help="also score leave-one-take-out: the default settings chosen, "
                             "the adapted model fitted and the ruptures penalty chosen "
                             "without the take scored")
    parser.add_argument("--pool", action="append", metavar="DIR",
                        help="with --loo, also choose on and learn from the labelled takes "
                             "under DIR, without scoring them (repeatable; default: the "
                             "folder the shipped settings were chosen on, when --data is "
                             "another)")
    parser.add_argument("--no-pool", action="store_true",
                        help="with --loo, choose on the other takes under --data only")
    subparsers = parser.add_subparsers(dest="command", metavar="command")
    add_speed(subparsers)
    curve = subparsers.add_parser(
        "learning-curve", help="how a studio's cut model learns from reviewed takes",
        description="Per labelled set: models fitted on k = 0, 1, 3, 5, 10 reviewed takes "
                    "of other subjects, scored on the held-out take; convention-following "
                    "and poisoning (benchmarks/quality/learning.py).")
    curve.add_argument("--data", help="benchmark data folder (default: $CUTROOM_BENCH_DATA "
                                      "or ../shared/data)")
    curve.set_defaults(handler=run_learning)
    parser.set_defaults(handler=run_quality, command="quality")  # no command: quality
    return parser


def run_learning(args) -> int:
    from benchmarks.quality import learning

    return learning.main(args.data)


def run_quality(args) -> int:
    return bench.main(args.data, args.method, loo=args.loo,
                      pool=[] if args.no_pool else args.pool)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    return run(build_parser(), argv, "benchmarks.quality")
