"""Another revision of the product, for a benchmark to run on: a git worktree of it, its
compiled parts built, and the environment in which this checkout's benchmarks import that
worktree's product.

The benchmark's own code is always this checkout's (the same benchmark, the same table);
only the product under test changes. Nothing of the old revision is copied into the tree
or loaded into the runner's process: the benchmark runs in a child process whose import
path puts the worktree first, and the worktree is removed afterwards.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from benchmarks.harness import PACKAGE


class RevisionError(ValueError):
    """A revision that names no commit, or whose worktree cannot be made."""


@dataclass
class Revision:
    tree: Path  # the worktree
    short: str
    subject: str

    def __str__(self) -> str:
        return f"{self.short} ({self.subject})"


def _git(*args, cwd=PACKAGE.parent) -> str:
    done = subprocess.run(["git", *args], cwd=cwd, capture_output=True, text=True)
    if done.returncode:
        raise RevisionError(f"git {' '.join(args)}: {done.stderr.strip() or 'failed'}")
    return done.stdout.strip()


def resolve(rev: str) -> tuple[str, str, str]:
    """(full hash, short hash, subject) of ``rev``; RevisionError naming it if it is none."""
    try:
        full = _git("rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}")
    except RevisionError:
        raise RevisionError(f"--against {rev}: no such commit in this repository") from None
    short, subject = _git("log", "-1", "--format=%h%x00%s", full).split("\0", 1)
    return full, short, subject


@contextlib.contextmanager
def worktree(rev: str):
    """A ``Revision`` checked out in a scratch git worktree with its C extensions built,
    removed at the end of the block."""
    full, short, subject = resolve(rev)
    tree = Path(tempfile.mkdtemp(prefix=f"cutroom-at-{short}-"))
    _git("worktree", "add", "--detach", "--force", str(tree), full)
    try:
        if (tree / "setup.py").exists():
            # The .so files are build products, never in git: the revision's own C.
            done = subprocess.run([sys.executable, "setup.py", "-q", "build_ext", "--inplace"],
                                  cwd=tree, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                  text=True)
            if done.returncode:
                raise RevisionError(f"--against {rev}: building its C extensions failed:\n"
                                    f"{done.stderr[-2000:]}")
        yield Revision(tree, short, subject)
    finally:
        with contextlib.suppress(RevisionError):
            _git("worktree", "remove", "--force", str(tree))
        shutil.rmtree(tree, ignore_errors=True)
        with contextlib.suppress(RevisionError):
            _git("worktree", "prune")


@contextlib.contextmanager
def launcher(revision: Revision | None):
    """(cwd, env) for a child process that imports this checkout's benchmarks and
    ``revision``'s product (this checkout's when None)."""
    env = dict(os.environ)
    if revision is None:
        yield PACKAGE.parent, env
        return
    from benchmarks.harness import data_dir

    # The child's first import path entry is its working folder: one holding only this
    # checkout's benchmarks package, so that the worktree's own benchmarks stay unseen.
    with tempfile.TemporaryDirectory(prefix="cutroom-bench-") as folder:
        (Path(folder) / "benchmarks").symlink_to(PACKAGE, target_is_directory=True)
        env.update(PYTHONPATH=os.pathsep.join(filter(None, [str(revision.tree),
                                                            env.get("PYTHONPATH")])),
                   CUTROOM_BENCH_TREE=str(revision.tree), CUTROOM_BENCH_REVISION=revision.short,
                   CUTROOM_BENCH_DATA=str(data_dir()))
        yield Path(folder), env
