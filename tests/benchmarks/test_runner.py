"""benchmarks/record.py writes a benchmark's output under a header saying how it was run."""

import re
import shlex
import subprocess
import sys

from benchmarks.record import REPO, main

PRINT_TABLE = "print('case  ms'); print('read  12.5')"


def test_it_writes_the_output_verbatim_under_date_commit_machine_and_load(tmp_path, capsys):
    path = tmp_path / "results" / "speed.md"
    assert main([str(path), "--", sys.executable, "-c", PRINT_TABLE]) == 0
    text = path.read_text()
    head, output = text.split("\n```text\n")
    assert output == "case  ms\nread  12.5\n```\n"
    assert head.startswith("# Benchmark results: speed\n")
    # The interpreter's path is shown as the command a reader types.
    assert f"from `python -c {shlex.quote(PRINT_TABLE)}`; do not edit." in head
    commit = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO,
                            capture_output=True, text=True).stdout.strip()
    assert re.search(rf"^- commit: {commit}( with uncommitted changes)?$", head, re.MULTILINE)
    assert re.search(r"^- date: \d{4}-\d\d-\d\d \d\d:\d\d UTC, \d+ s$", head, re.MULTILINE)
    assert re.search(r"^- machine: .+, \d+ cores, Python 3\.\d+", head, re.MULTILINE)
    assert re.search(r"^- load average \(1, 5, 15 min\): [\d. ]+ at the start, [\d. ]+ at the "
                     r"end$", head, re.MULTILINE)
    assert capsys.readouterr().out == f"wrote {path}\n"


def test_a_failed_run_leaves_the_results_as_they_were(tmp_path, capsys):
    path = tmp_path / "quality.md"
    path.write_text("the last good run\n")
    failing = "import sys; print('half a table'); sys.exit(3)"
    assert main([str(path), "--", sys.executable, "-c", failing]) == 3
    assert path.read_text() == "the last good run\n"
    assert "exited with 3" in capsys.readouterr().err
