"""Timing and tables: a call timed as a request is (wall and CPU time, after a warm-up
run), the median and 95th percentile of a series, and a fixed-width table printed row by
row, so that a long benchmark shows its progress."""

from __future__ import annotations

import statistics
import time
from dataclasses import dataclass


def timed(call, repeat: int, warm: int = 1):
    """``call()`` run ``warm`` times untimed, then ``repeat`` times: (wall ms, CPU ms) of
    each timed run, and the last result."""
    walls, cpus, result = [], [], None
    for i in range(warm + repeat):
        started, used = time.perf_counter(), time.process_time()
        result = call()
        wall, cpu = time.perf_counter() - started, time.process_time() - used
        if i >= warm:
            walls.append(wall * 1000)
            cpus.append(cpu * 1000)
    return walls, cpus, result


def median(values) -> float:
    return statistics.median(values) if values else float("nan")


def p95(values) -> float:
    """The 95th percentile of ``values`` (the value itself for a single one)."""
    if not values:
        return float("nan")
    return statistics.quantiles(values, n=20)[-1] if len(values) > 1 else values[0]


@dataclass
class Table:
    """Columns as (title, width, format): ``print_header()`` once, then ``row(*cells)``.

    A width < 0 left-aligns the column; a format applies to numbers only (text is printed
    as it is), e.g. ``Table([("query", -29, ""), ("med", 8, ".1f")])``.
    """

    columns: list[tuple[str, int, str]]

    def _line(self, cells) -> str:
        out = []
        for (_, width, fmt), cell in zip(self.columns, cells, strict=True):
            text = format(cell, fmt) if isinstance(cell, (int, float)) and fmt else str(cell)
            out.append(text.ljust(-width) if width < 0 else text.rjust(width))
        return " ".join(out).rstrip()

    def print_header(self) -> None:
        header = self._line([title for title, _, _ in self.columns])
        print(header)
        print("-" * len(header))

    def row(self, *cells) -> None:
        print(self._line(cells), flush=True)
