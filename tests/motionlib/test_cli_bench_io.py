"""python -m motionlib.bench io prints its table (speed is read from it, never asserted)."""

import subprocess
import sys

import pytest


@pytest.mark.slow
def test_it_prints_the_io_table(bvh_13_29):
    data = bvh_13_29.parents[2]
    result = subprocess.run([sys.executable, "-m", "motionlib.bench", "io", "--runs", "2",
                             "--data", str(data)], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    lines = result.stdout.splitlines()
    assert lines[0].split()[:7] == ["case", "wall", "ms", "min", "ms", "cpu", "ms"]
    for case in ("read+FK 13_29.bvh", "read+FK 13_29.amc", "bvh package parse 13_29.bvh",
                 "synth.generate 5 min"):
        assert any(case in line for line in lines), case
    assert any(line.startswith("speed-up over the bvh package") for line in lines)


def test_it_says_when_the_captures_are_missing(tmp_path):
    result = subprocess.run([sys.executable, "-m", "motionlib.bench", "io", "--data",
                             str(tmp_path)], capture_output=True, text=True)
    assert result.returncode == 2
    assert result.stderr.startswith("motionlib.bench io: error: CMU captures not found under")
