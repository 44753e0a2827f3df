"""matplotlib is an optional extra: without it, ``segment --plot`` fails with one clear
line (before reading the take) and everything else still runs."""

import subprocess
import sys

import pytest

from motionlib import synth, write_bvh

# A fresh interpreter where ``import matplotlib`` fails as it does when the extra is not
# installed (a None entry in sys.modules makes the import raise ImportError).
WITHOUT_MATPLOTLIB = r"""
import sys
sys.modules["matplotlib"] = None
from motionlib.cli import main
sys.exit(main(sys.argv[1:]))
"""


@pytest.fixture(scope="module")
def bvh_path(tmp_path_factory):
    take, _ = synth.generate(seed=3, fps=30.0, duration=20.0)
    path = tmp_path_factory.mktemp("takes") / "synth.bvh"
    write_bvh(take, path)
    return path


def run_without_matplotlib(*args):
    return subprocess.run([sys.executable, "-c", WITHOUT_MATPLOTLIB, *map(str, args)],
                          capture_output=True, text=True)


def test_it_says_plot_needs_the_matplotlib_extra(bvh_path, tmp_path):
    out = tmp_path / "cuts.png"
    done = run_without_matplotlib("segment", bvh_path, "--plot", out)
    assert done.returncode == 2
    assert done.stderr == ('motionlib segment: error: --plot: drawing needs matplotlib, which '
                           'is not installed (pip install "cutroom[plot]")\n')
    assert not out.exists()


def test_it_says_so_before_reading_the_take(tmp_path):
    done = run_without_matplotlib("segment", tmp_path / "missing.bvh", "--plot",
                                  tmp_path / "cuts.png")
    assert done.returncode == 2
    assert "--plot: drawing needs matplotlib" in done.stderr


def test_it_segments_without_matplotlib_when_no_plot_is_asked_for(bvh_path):
    done = run_without_matplotlib("segment", bvh_path, "--json")
    assert done.returncode == 0, done.stderr
    assert '"cuts"' in done.stdout
