import math

import pytest

from motionlib import benchdata, benchmark

DATA = benchdata.data_dir()


def row(f1, err):
    base = {key: 0.5 for _, key in benchmark.COLUMNS}
    return {**base, "f1@1s": f1, "median_error_s": err}


def test_it_averages_each_method_over_the_takes_skipping_missing_errors():
    results = {"a": {"m": row(1.0, float("nan"))}, "b": {"m": row(0.5, 0.2)}}
    mean = benchmark.mean_rows(results)["m"]
    assert mean["f1@1s"] == 0.75
    assert mean["median_error_s"] == 0.2


def test_it_prints_one_line_per_method_under_a_header():
    text = benchmark.format_table("13_30", {"default": row(0.9, 0.1), "ppca": row(0.1, math.nan)})
    lines = text.splitlines()
    assert lines[0] == "13_30"
    assert lines[1].split()[:2] == ["method", "P@.5s"]
    assert lines[3].startswith("default") and "0.900" in lines[3]
    assert lines[4].startswith("ppca") and "nan" in lines[4]


def test_it_fails_cleanly_without_the_data_folder(tmp_path, capsys):
    assert benchmark.main(tmp_path / "missing") == 2
    assert "benchmark data folder not found" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.skipif(not DATA.is_dir(), reason=f"CMU benchmark data not found at {DATA}")
def test_it_scores_a_method_on_every_labelled_take():
    results = benchmark.run(only=["bone_angle"])
    skeleton = [name for name in results if "4 channels" not in name]
    assert skeleton == ["13_29", "13_30", "86_01"]
    for name in skeleton:
        assert 0 <= results[name]["bone_angle"]["f1@1s"] <= 1
        assert results[name]["bone_angle"]["n_cuts"] > 0


@pytest.mark.slow
@pytest.mark.skipif(not DATA.is_dir(), reason=f"CMU benchmark data not found at {DATA}")
def test_it_runs_only_skeleton_free_methods_on_four_channel_takes():
    results = benchmark.run(only=["bone_angle", "default"])
    four = [rows for name, rows in results.items() if name.endswith("(4 channels)")]
    assert len(four) == 8
    assert all(list(rows) == ["default"] for rows in four)


@pytest.mark.slow
@pytest.mark.skipif(not DATA.is_dir(), reason=f"CMU benchmark data not found at {DATA}")
def test_it_reports_the_patent_run_beside_the_published_cuts():
    lines = benchmark.patent_comparison(DATA).splitlines()
    assert lines[1].split(":", 1)[1].strip() == str(benchmark.PATENT_13_30["initial"])
    final_diff = [line for line in lines if "max difference" in line][-1]
    assert int(final_diff.split(":")[1].split()[0]) <= 30
