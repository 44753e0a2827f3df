"""The machine a benchmark runs on and the load it runs under: the load average, a line
naming the machine, busy processes for a load one can state, the kernel's proactive
reclaim, and how much of a mapped file is resident."""

import contextlib
import functools
import os
import platform
import subprocess
import sys
from pathlib import Path


def load():
    """The load average (1, 5, 15 min) as a benchmark prints it: "1.2, 0.8, 0.5"."""
    return ", ".join(f"{x:.1f}" for x in os.getloadavg())


def machine():
    """The machine as a results header names it: system, architecture, cores, Python."""
    return (f"{platform.system()} {platform.machine()}, {os.cpu_count()} cores, "
            f"Python {platform.python_version()}")


@contextlib.contextmanager
def busy(n, nice=0):
    """``n`` processes spinning on a core (``while True: pass``) for the length of the
    block, killed at its end: a benchmark's times under a load one can state and repeat.

    They run at nice ``nice`` whatever the caller's niceness (when it may lower it): 0, the
    default, competes with the benchmark as ordinary requests' neighbours would; 10 is
    the service's own workers, which ``scripts/up.py`` runs at nice 10.
    """
    spinners = [subprocess.Popen([sys.executable, "-c", "while True: pass"],
                                 preexec_fn=functools.partial(_set_nice, nice)) for _ in range(n)]
    try:
        yield spinners
    finally:
        for proc in spinners:
            proc.kill()
        for proc in spinners:
            proc.wait()


def _set_nice(nice):
    with contextlib.suppress(PermissionError):
        os.setpriority(os.PRIO_PROCESS, 0, nice)


def mapped_rss(name):
    """kB of the memory maps of files whose path ends with ``name`` resident in this
    process: (Rss, Pss), from ``/proc/self/smaps``."""
    rss = pss = 0
    inside = False
    with open("/proc/self/smaps") as fh:
        for line in fh:
            if "-" in line.split(" ", 1)[0]:
                inside = line.rstrip().endswith(name)
            elif inside and line.startswith("Rss:"):
                rss += int(line.split()[1])
            elif inside and line.startswith("Pss:"):
                pss += int(line.split()[1])
    return rss, pss


def reclaim():
    """The kernel's proactive reclaim, as a benchmark prints it: DAMON schemes that page out
    memory idle for a while take file pages (the index files, PostgreSQL's files) out of
    the page cache whatever memory is free, so a later read of them goes to the disk."""
    root = Path("/sys/kernel/mm/damon/admin/kdamonds")
    found = []
    for kdamond in sorted(root.glob("[0-9]*")):
        try:
            if (kdamond / "state").read_text().strip() != "on":
                continue
            for context in sorted((kdamond / "contexts").glob("[0-9]*")):
                aggr = int((context / "monitoring_attrs/intervals/aggr_us").read_text())
                for scheme in sorted((context / "schemes").glob("[0-9]*")):
                    action = (scheme / "action").read_text().strip()
                    age = int((scheme / "access_pattern/age/min").read_text())
                    if action == "pageout":
                        found.append(f"pages idle >= {age * aggr / 1e6:.0f} s paged out")
        except (OSError, ValueError):
            continue
    return f"proactive reclaim (DAMON): {', '.join(found)}" if found else "no proactive reclaim"
