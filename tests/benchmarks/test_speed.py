"""python -m benchmarks speed-io prints its table (speed is read from it, never asserted)."""

import pytest

from benchmarks.quality.cli import main

CASES = ["motionlib read+FK 13_29.bvh", "motionlib read+FK 13_29.amc",
         "bvh package parse 13_29.bvh", "synth.generate 5 min @120fps"]


def table_rows(lines):
    """case -> (wall ms, min ms, cpu ms, runs, peak MiB, file MiB, peak/file) from the table."""
    rows = {}
    for line in lines[1:1 + len(CASES)]:
        cells = [None if cell == "-" else float(cell) for cell in line[30:].split()]
        rows[line[:30].strip()] = cells
    return rows


def value_after(lines, prefix, separator):
    line = next(line for line in lines if line.startswith(prefix))
    return float(line.split(separator, 1)[1].split("x")[0].split()[0])


@pytest.mark.slow
def test_it_prints_numbers_that_agree_with_each_other(shared_data, capsys):
    if not (shared_data / "cmu" / "bvh" / "13_29.bvh").is_file():
        pytest.skip(f"real CMU capture 13_29.bvh is not available under {shared_data}")
    assert main(["speed", "io", "--runs", "2", "--data", str(shared_data)]) == 0
    lines = capsys.readouterr().out.splitlines()
    rows = table_rows(lines)
    assert list(rows) == CASES
    # The bvh package runs every fourth round only: once in two rounds.
    assert [row[3] for row in rows.values()] == [2, 2, 1, 2]
    for wall, fastest, _, _, peak, size, ratio in rows.values():
        assert 0 < fastest <= wall and peak > 0
        if size is not None:
            assert ratio == pytest.approx(peak / size, abs=0.02)
    ours, theirs = rows[CASES[0]][0], rows[CASES[2]][0]
    assert value_after(lines, "speed-up over the bvh package", ":") == \
        pytest.approx(theirs / ours, rel=0.05, abs=0.1)
    assert value_after(lines, "peak memory of read+FK 13_29.bvh", ":") == rows[CASES[0]][6]


def test_it_says_when_the_captures_are_missing(tmp_path, capsys):
    assert main(["speed", "io", "--data", str(tmp_path)]) == 2
    assert capsys.readouterr().err.startswith(
        "benchmarks.quality speed io: error: CMU captures not found under")


def test_the_adapt_benchmark_times_the_model_format_the_learner_learns(capsys):
    assert main(["speed", "adapt", "--takes", "3", "--minutes", "0.5", "--runs", "1"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1] == "format 2, candidate scorer (now)"
    for block in (lines[2:6],):
        cases = [line[:58].strip() for line in block]
        assert cases == ["detect, zero-shot, 0.5-min 120 fps take",
                         "detect, with a model, 0.5-min 120 fps take",
                         "fit on 3 0.5-min 120 fps takes, none stored",
                         "refit, 1 of 3 changed, studies stored"]
        for line in block:
            wall, cpu = (float(v) for v in line[58:].split()[:2])
            assert wall > 0 and cpu > 0
        for line in block[1:]:
            assert float(line[58:].split()[2]) > 0  # the target
