"""Work on a long take split over the machine's cores.

The compiled readers and the forward kinematics let the GIL go while they run, so the
halves of a long take run at once in two threads of one process: an hour-long BVH is read
and walked in about half the time on two cores. Short inputs stay in one thread (a thread
costs more than it saves there).

``MOTIONLIB_THREADS`` sets how many threads at most (default: the cores, at most
``MAX_THREADS``); 1 turns it off. Results do not depend on it: each part computes what the
whole would have computed for its rows.
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

MAX_THREADS = 2


def threads() -> int:
    """How many threads a long take's work may use."""
    configured = os.environ.get("MOTIONLIB_THREADS", "")
    if configured.strip().isdigit() and int(configured) > 0:
        return int(configured)
    return max(1, min(MAX_THREADS, os.cpu_count() or 1))


def run_all(tasks: list[Callable[[], object]]) -> list[object]:
    """Each task's result, the first in this thread and the others in threads of their own;
    the first error raised by any of them is raised here once all have ended."""
    if not tasks:
        return []
    results: list[object] = [None] * len(tasks)
    errors: list[BaseException] = []

    def run(i):
        try:
            results[i] = tasks[i]()
        except BaseException as exc:  # noqa: BLE001 - raised again in the caller's thread
            errors.append(exc)

    others = [threading.Thread(target=run, args=(i,), daemon=True) for i in range(1, len(tasks))]
    for t in others:
        t.start()
    run(0)
    for t in others:
        t.join()
    if errors:
        raise errors[0]
    return results


def bounds(n: int, parts: int) -> list[tuple[int, int]]:
    """``parts`` consecutive ranges [start, stop) covering 0 .. n, as even as can be."""
    edges = [n * k // parts for k in range(parts + 1)]
    return [(a, b) for a, b in zip(edges, edges[1:], strict=False) if b > a]
