"""``python -m motionlib`` is the library's own command line: info, convert and segment,
nothing of the benchmarks (those are ``python -m benchmarks quality``)."""

import re
import subprocess
import sys


def test_its_help_lists_exactly_info_convert_and_segment():
    done = subprocess.run([sys.executable, "-m", "motionlib", "--help"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    # argparse lists each command on its own line under "command", indented four spaces.
    listed = re.findall(r"^    (\S+)\s+\S", done.stdout.split("positional arguments:")[1]
                        .split("options:")[0], flags=re.MULTILINE)
    assert listed == ["info", "convert", "segment"]


def test_it_refuses_the_benchmark_commands_it_used_to_have():
    for old in ("bench", "bench-quality", "bench-speed"):
        done = subprocess.run([sys.executable, "-m", "motionlib", old],
                              capture_output=True, text=True)
        assert done.returncode == 2
        assert f"invalid choice: '{old}'" in done.stderr


# What a fresh interpreter has imported once the command line is built, as every
# `python -m motionlib` command builds it before running.
LOADED = r"""
import sys
from motionlib.cli import build_parser
build_parser()
print("\n".join(sorted(sys.modules)))
"""


def test_building_it_imports_no_benchmark_tuning_or_plotting_module():
    done = subprocess.run([sys.executable, "-c", LOADED], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    loaded = done.stdout.split()
    assert [m for m in loaded if re.search(r"bench|tuning", m)] == []
    assert [m for m in loaded if m.split(".")[0] in ("matplotlib", "ruptures", "claspy")] == []
