"""The one way to run a benchmark.

    python -m benchmarks                       # the benchmarks, by name
    python -m benchmarks NAME                  # run NAME, record benchmarks/results/NAME.md
    python -m benchmarks NAME --against REV    # the same, on REV's product too, same run
    python -m benchmarks NAME -- ARGS          # with arguments of its own: printed only

The benchmark runs in a child process and its table is echoed as it comes. With
``--against REV`` it runs first on a git worktree of REV (``harness.against``), then on
this checkout, one after the other under the same load, and the results file holds both
tables. A run with arguments other than the registered ones is not recorded (its figures
are not the ones the docs cite) unless ``--record`` says so; a failed run records nothing.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from datetime import UTC, datetime

from benchmarks.harness import RESULTS, against, record
from benchmarks.harness.machine import load
from benchmarks.registry import BENCHMARKS


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m benchmarks",
                                     description="Run a benchmark by name; with no name, "
                                                 "list them.")
    parser.add_argument("name", nargs="?", help="the benchmark (none: list them)")
    parser.add_argument("--against", metavar="REV",
                        help="also run it on this git revision's product, from a worktree")
    parser.add_argument("--record", action="store_true",
                        help="record to benchmarks/results/NAME.md even with arguments")
    parser.add_argument("--no-record", action="store_true", help="print only")
    parser.add_argument("args", nargs="*", help="after --: the benchmark's own arguments")
    return parser


def listing() -> str:
    width = max(map(len, BENCHMARKS))
    lines = ["usage: python -m benchmarks NAME [--against REV] [-- ARGS]", ""]
    lines += [f"  {name:<{width}}  {bench.about}" for name, bench in BENCHMARKS.items()]
    return "\n".join(lines)


def run_child(name: str, args: list[str], revision: against.Revision | None):
    """Run benchmark ``name`` in a child process (on ``revision``'s product, or this
    checkout's); echo and return its stdout, or None when it failed."""
    command = [sys.executable, "-m", "benchmarks.harness.child", name, *args]
    with against.launcher(revision) as (cwd, env):
        proc = subprocess.Popen(command, cwd=cwd, env=env, stdout=subprocess.PIPE, text=True)
        lines = []
        for line in proc.stdout:
            sys.stdout.write(line)
            sys.stdout.flush()
            lines.append(line)
        status = proc.wait()
    if status:
        print(f"benchmarks: {name} exited with {status}", file=sys.stderr)
        return None
    return "".join(lines)


def run(name: str, args: list[str], rev: str | None) -> tuple[str | None, str]:
    """The output of ``name`` (on ``rev``, then this checkout, when ``rev`` is given) and
    the revision compared against, as the header names it."""
    if rev is None:
        return run_child(name, args, None), ""
    with against.worktree(rev) as revision:
        print(f"## {name} at {revision}, from a git worktree (load {load()})\n", flush=True)
        old = run_child(name, args, revision)
    if old is None:
        return None, str(revision)
    head = record.commit()
    print(f"\n## {name} at this checkout, {head} (load {load()})\n", flush=True)
    new = run_child(name, args, None)
    if new is None:
        return None, str(revision)
    return (f"## at {revision}, from a git worktree\n\n{old}\n"
            f"## at this checkout, {head}\n\n{new}"), str(revision)


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    opts = parser.parse_intermixed_args(argv)
    if opts.name is None:
        print(listing())
        return 0
    if opts.name not in BENCHMARKS:
        parser.error(f"no benchmark named {opts.name!r}; `python -m benchmarks` lists them")
    bench = BENCHMARKS[opts.name]
    args = [*bench.args, *opts.args]
    started, loads, clock = datetime.now(UTC), [record.load()], time.perf_counter()
    try:
        output, compared = run(opts.name, args, opts.against)
    except against.RevisionError as error:
        parser.exit(2, f"{parser.prog}: error: {error}\n")
    if output is None:
        return 1
    if opts.no_record or (opts.args and not opts.record):
        return 0
    shown = " ".join(["python -m benchmarks", opts.name, *(["--against", opts.against]
                                                           if opts.against else []),
                      *(["--", *opts.args] if opts.args else [])])
    path = RESULTS / f"{opts.name}.md"
    loads.append(record.load())
    record.write(path, record.Run(opts.name, shown, started, time.perf_counter() - clock,
                                  tuple(loads), record.commit(), compared), output)
    print(f"wrote {path.relative_to(RESULTS.parents[1])}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
