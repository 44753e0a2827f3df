import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from benchmarks.quality import bench, checks, data, tables, tuning, unmatched, variants
from motionlib import adapt, metrics, shared_data, synth
from motionlib.segmenters import get_segmenter
from motionlib.segmenters.default import Default

DATA = shared_data.data_dir()
REPO = Path(__file__).resolve().parents[2]


def row(f1, err):
    base = {key: 0.5 for _, key in tables.COLUMNS}
    return {**base, "f1@1s": f1, "median_error_s": err}


def test_it_averages_each_method_over_the_takes_skipping_missing_errors():
    results = {"a": {"m": row(1.0, float("nan"))}, "b": {"m": row(0.5, 0.2)}}
    mean = tables.mean_rows(results)["m"]
    assert mean["f1@1s"] == 0.75
    assert mean["median_error_s"] == 0.2


def test_it_prints_one_line_per_method_under_a_header():
    text = tables.format_table("13_30", {"default": row(0.9, 0.1), "ppca": row(0.1, math.nan)})
    lines = text.splitlines()
    assert lines[0] == "13_30"
    assert lines[1].split()[:2] == ["method", "P@.5s"]
    assert lines[3].startswith("default") and "0.900" in lines[3]
    assert lines[4].startswith("ppca") and "nan" in lines[4]


def test_it_fails_cleanly_without_the_data_folder(tmp_path, capsys):
    assert bench.main(tmp_path / "missing") == 2
    assert "benchmark data folder not found" in capsys.readouterr().err


@pytest.mark.slow
@pytest.mark.skipif(not DATA.is_dir(), reason=f"CMU benchmark data not found at {DATA}")
def test_it_scores_each_take_against_its_own_labels():
    results = bench.run(only=["bone_angle"])
    skeleton = [name for name in results if "4 channels" not in name]
    assert skeleton == ["13_29", "13_30", "86_01"]
    for labelled in data.labelled_takes():
        take = labelled.read()
        cuts = get_segmenter("bone_angle")().fit_predict(take).cuts
        expected = metrics.evaluate(cuts, labelled.truth, fps=take.fps)
        row = results[labelled.name]["bone_angle"]
        assert row["n_cuts"] == len(cuts) > 0
        assert {key: row[key] for key in expected} == pytest.approx(expected, nan_ok=True)


@pytest.mark.slow
@pytest.mark.skipif(not DATA.is_dir(), reason=f"CMU benchmark data not found at {DATA}")
def test_it_runs_only_skeleton_free_methods_on_four_channel_takes():
    results = bench.run(only=["bone_angle", "default"])
    four = [rows for name, rows in results.items() if name.endswith("(4 channels)")]
    assert len(four) == 8
    assert all(list(rows) == ["default"] for rows in four)


@pytest.mark.slow
@pytest.mark.skipif(not DATA.is_dir(), reason=f"CMU benchmark data not found at {DATA}")
def test_it_reports_the_patent_run_beside_the_published_cuts():
    text = bench.patent_comparison(DATA)
    lists = {line.split(":")[0].strip(): json.loads(line.split(":", 1)[1])
             for line in text.splitlines()[1:] if "[" in line}
    differences = [int(line.split(":")[1].split()[0])
                   for line in text.splitlines() if "max difference" in line]
    for stage, difference in zip(("initial", "final"), differences, strict=True):
        ours, published = np.array(lists[f"{stage} ours"]), lists[f"{stage} published"]
        assert difference == np.abs(ours - published).max(), stage
    assert differences[-1] <= 30


def test_it_gives_the_adaptation_each_other_capture_once_in_the_scored_takes_kind():

    def view(name, kind, source="kruger2017"):
        truth = np.array([[90, 100, 110]])
        take = data.ChannelTake(name=f"{name}-{kind}", fps=120.0,
                                     channels=np.zeros((300, 4)))
        return tuning.TakeCache(data.LabelledTake(name, None, None, truth, source, kind),
                                take)

    cache = [view("a", "skeleton"), view("a", "channels"), view("b", "channels"),
             view("c", "skeleton"), view("d", "channels", source="mocap6")]
    names = [take.name for take, _ in bench._examples(cache, cache[2])]
    assert names == ["a-channels", "c-skeleton"]
    names = [take.name for take, _ in bench._examples(cache, cache[3])]
    assert names == ["a-skeleton", "b-channels"]


def test_it_runs_as_python_m_benchmarks_quality(tmp_path):
    done = subprocess.run([sys.executable, "-m", "benchmarks", "quality", "--", "--data",
                           str(tmp_path / "missing")], capture_output=True, text=True,
                          cwd=REPO)
    assert done.returncode == 1
    assert "benchmark data folder not found" in done.stderr
    assert "quality exited with 2" in done.stderr


def test_it_summarises_placement_by_kind_of_take():
    results = {
        "a": {"default": {"median_error_s": 0.1, "in_window": float("nan")}},
        "b": {"default": {"median_error_s": 0.3, "in_window": 1.0}},
        "c": {"default": {"median_error_s": 0.4, "in_window": 0.5}},
        "d": {"default": {"median_error_s": 0.6, "in_window": 0.7}},
    }
    text = tables.placement_summary(results, [("full-skeleton", ["a", "b"]),
                                                     ("four-channel", ["c", "d"])])
    line = text.splitlines()[1]
    assert line.split()[0] == "default"
    assert "full-skeleton 0.200 s, in window 1.00 (1 take)" in line
    assert "four-channel 0.500 s, in window 0.60 (2 takes)" in line


class _Labelled:
    """A labelled synthetic take, as ``data.LabelledTake`` is read by the check."""

    def __init__(self, seed, kind="skeleton"):
        self.take, segments = synth.generate(seed=seed, fps=30.0, duration=40.0)
        cuts = np.asarray([s[0] for s in segments[1:]])
        self.truth = np.repeat(cuts[:, None], 3, axis=1)
        self.kind, self.name = kind, f"seed {seed}"

    def read(self):
        return self.take


def _read(takes):
    """The (labelled take, motion) pairs the bench hands the checks."""
    return [(t, t.read()) for t in takes]


def test_the_real_short_activity_check_shortens_every_inner_activity_of_each_skeleton_take():
    takes = [_Labelled(1), _Labelled(2), _Labelled(3, kind="channels")]
    text = checks.real_short_activity_check(_read(takes), seconds=(1.8, 2.5))
    expected = {d: sum(variants.shortened(t.take, t.truth, k, d) is not None
                       for t in takes[:2] for k in range(len(t.truth) - 1)) for d in (1.8, 2.5)}
    lines = text.splitlines()
    assert f"({expected[1.8]} / {expected[2.5]} cases)" in lines[0]
    assert [line.split("  ")[1].strip() for line in lines[2:]] == [
        "zero-shot", "short_unmatched=0", "short_activity=4/uniformity=0.3", "windows 2-4 s",
        "adapted"]
    for line in lines[2:]:
        both, sides, _, both2, sides2, _ = line.split()[-6:]
        assert both.endswith(f"/{expected[1.8]}") and sides.endswith(f"/{2 * expected[1.8]}")
        assert both2.endswith(f"/{expected[2.5]}") and sides2.endswith(f"/{2 * expected[2.5]}")
        assert int(both.split("/")[0]) <= int(sides.split("/")[0])


def test_the_real_short_activity_check_says_so_without_a_skeleton_take():
    text = checks.real_short_activity_check(_read([_Labelled(1, kind="channels")]))
    assert text == "short activities, real motion: no full-skeleton take"


def test_the_real_short_activity_check_has_no_adapted_row_with_one_skeleton_take():
    text = checks.real_short_activity_check(_read([_Labelled(1)]), seconds=(1.8,))
    rows = [line.split("  ")[1].strip() for line in text.splitlines()[2:]]
    assert rows == ["zero-shot", "short_unmatched=0", "short_activity=4/uniformity=0.3",
                    "windows 2-4 s"]


def test_the_edge_activity_check_finds_the_boundary_of_a_short_first_or_last_activity():
    takes = [_Labelled(1), _Labelled(2), _Labelled(3, kind="channels")]
    text = checks.edge_activity_check(_read(takes), seconds=(2.5, 60.0))
    cases = sum(variants.trimmed(t.take, t.truth, side, 2.5) is not None
                for t in takes[:2] for side in ("first", "last"))
    assert "each of the 2 full-skeleton takes" in text
    found = int(text.split("2.5 s ")[1].split("/")[0])
    # Synthetic activities differ by construction: at 2.5 s every boundary is found.
    assert f"2.5 s {found}/{cases} (false cuts" in text and found == cases > 0
    assert "60 s 0/0 (false cuts 0)" in text  # no activity is that long: no case
    assert checks.edge_activity_check(_read([takes[2]])) == \
        "short activities at the ends of a take: no full-skeleton take with a cut"


def test_the_short_activity_checks_run_beside_a_take_labelled_as_one_activity():
    # A take whose labels hold no cut (one activity throughout) has no boundary to shorten
    # or trim; the checks go on with the others instead of stopping the benchmark.
    whole = _Labelled(4)
    whole.truth = np.zeros((0, 3), dtype=np.int64)
    takes = _read([_Labelled(1), whole])
    edge = checks.edge_activity_check(takes, seconds=(2.5,))
    assert "each of the 1 full-skeleton takes" in edge and "2.5 s " in edge
    assert checks.edge_activity_check(takes[1:]) == \
        "short activities at the ends of a take: no full-skeleton take with a cut"
    inner = checks.real_short_activity_check(takes, seconds=(2.5,))
    assert inner.splitlines()[-1].split()[0] == "adapted"
    throughout = checks.short_takes_check(takes, seconds=(2.5,))
    assert [line.split()[0] for line in throughout.splitlines()[2:]] == ["zero-shot", "adapted"]


def test_the_short_takes_check_scores_zero_shot_and_adapted_on_takes_cut_down_throughout():
    takes = [_Labelled(1), _Labelled(2), _Labelled(3, kind="channels")]
    text = checks.short_takes_check(_read(takes), seconds=(2.5, 60.0))
    lines = text.splitlines()
    assert "every inner activity of the 2 full-skeleton takes cut down to 2.5 / 60 s" in lines[0]
    assert [line.split()[0] for line in lines[2:]] == ["zero-shot", "adapted"]
    # At 60 s no activity is cut down: the takes as they are, whose synthetic activities
    # the zero-shot detector finds.
    zero = [float(v) for v in lines[2].split()[1:]]
    expected = np.mean([metrics.evaluate(
        adapt.detect(t.take).cuts, t.truth, fps=t.take.fps)["f1@1s"]
        for t in takes[:2]])
    assert zero[2] == pytest.approx(expected, abs=5e-4) and zero[2] > 0.8
    assert all(0 <= v <= 1 for v in zero[::2])
    one = checks.short_takes_check(_read([takes[0]]), seconds=(2.5,))
    assert [line.split()[0] for line in one.splitlines()[2:]] == ["zero-shot"]
    assert checks.short_takes_check(_read([takes[2]])) == \
        "short activities throughout a take: no full-skeleton take"


def test_the_unmatched_choice_check_leaves_out_each_skeleton_take_and_scores_it():
    takes = [_Labelled(1), _Labelled(2), _Labelled(3, kind="channels")]
    lines = unmatched.unmatched_choice_check(_read(takes)).splitlines()
    assert "chosen leave-one-take-out" in lines[0]
    named = [line[2:12].strip() for line in lines[2:-2] if line[2:12].strip()]
    assert named == ["seed 1", "seed 2", "all"]  # each skeleton take left out, then totals
    cases = sum(variants.shortened(t.take, t.truth, k, s) is not None
                for t in takes[:2] for k in range(len(t.truth) - 1)
                for s in unmatched.UNMATCHED_INNER_S)
    chosen, off = lines[-4], lines[-3]
    assert chosen.split()[:2] == ["all", "chosen"] and off.split()[0] == "off"
    for line in (chosen, off):  # both sides counted over every case left out
        assert line.split()[-2].endswith(f"/{cases}")
    assert lines[-2].startswith("  chosen on all: ")
    assert lines[-2].endswith(f"shipped: short_unmatched "
                              f"{Default.params['short_unmatched'].default:g}, half-width "
                              f"{Default.unmatched_half_s:g} s")
    assert lines[-1].startswith("  take-median guard")  # what the guard keeps of the firings


def test_the_guard_line_counts_the_firings_it_keeps():
    relative = Default.unmatched_relative

    line = unmatched._guard_line([relative - 1, relative, 9.0])
    assert "of the 3 firings on this material without it, 2 kept" in line
    assert line.endswith(f"from {relative - 1:.1f} (median {relative:.1f})")
    assert unmatched._guard_line([]) == \
        "take-median guard: the step fires nowhere on this material"


def test_the_guard_check_runs_on_the_takes_without_labels(tmp_path):
    (tmp_path / "cmu/bvh").mkdir(parents=True)
    (tmp_path / "labels").mkdir()
    take, _ = synth.generate(seed=3, fps=60.0, duration=20.0)
    from motionlib import write_bvh

    write_bvh(take, tmp_path / "cmu/bvh/55_01.bvh")
    lines = unmatched.unmatched_guard_check(tmp_path).splitlines()
    assert lines[1].split() == ["take", "s", "shipped", "step", "off", "firings"]
    assert lines[2].split()[:2] == ["55_01", "20.0"]
    (tmp_path / "empty").mkdir()
    assert unmatched.unmatched_guard_check(tmp_path / "empty") == \
        "unmatched-poses step on takes without labels: none under the data folder"


def test_the_unmatched_choice_check_says_so_without_a_skeleton_take():
    text = unmatched.unmatched_choice_check(_read([_Labelled(1, kind="channels")]))
    assert text == "unmatched-poses step: no full-skeleton take to choose its settings on"


def test_the_long_take_check_scores_each_labelled_part_without_what_lies_by_a_join():
    fps = 60.0
    first, _ = synth.generate(seed=4, fps=fps, duration=20.0)
    second, _ = synth.generate(seed=5, fps=fps, duration=20.0)
    n, gap = first.n_frames, int(checks.JOIN_S * fps)
    # True cuts of the first take: one in its span, one within JOIN_S of its end (a join).
    truth = np.repeat(np.array([[300], [n - gap // 2]]), 3, axis=1)
    labelled = data.LabelledTake("a", None, None, truth, "mocap6")
    # Alone: the first true cut found, and a cut by the join that is not scored either.
    alone = {"a": np.array([300, n - gap // 4])}
    [(name, joined, own)] = checks._part_rows(
        [("a", first, labelled), ("b", second, None)], alone)
    assert name == "a"
    assert own["f1@1s"] == 1.0 and own["edits_per_cut"] == 0.0
    assert 0.0 <= joined["f1@1s"] <= 1.0
    # Last in the joined take, the same part keeps a true cut near its end: that is the
    # take's end, not a join.
    [(_, _, own_last)] = checks._part_rows(
        [("b", second, None), ("a", first, labelled)], alone)
    assert own_last["f1@1s"] == 1.0


@pytest.mark.slow
def test_the_long_take_check_joins_the_takes_of_one_skeleton_both_ways():
    if not (DATA / "cmu/amc/13_30.amc").is_file():
        pytest.skip("labelled CMU takes are not available (needs ../shared/data)")
    lines = checks.long_take_check(DATA).splitlines()
    assert lines[0].startswith("long takes, real motion")
    joined = {tuple(line.split()[:4:2]) for line in lines[2:-1]}
    assert {("13_29", "13_30"), ("13_30", "13_29"), ("13_17", "13_29")} <= joined
    assert lines[-1].startswith("  mean over ")
    assert checks.long_take_check(DATA / "cmu") == \
        "long takes: no skeleton with two AMC takes, one of them labelled, here"


def test_the_tempo_check_scores_each_kind_of_take_played_slower_and_quicker():
    takes = [_Labelled(1), _Labelled(2, kind="channels")]
    text = checks.tempo_check(_read(takes), speeds=(0.8, 1.0))
    lines = text.splitlines()
    assert "played at 0.8 / 1 times its pace" in lines[0]
    assert [line[:30].strip() for line in lines[2:]] == [
        "full-skeleton, shipped", "full-skeleton, tempo", "four-channel, shipped",
        "four-channel, tempo"]
    # At its own pace, the shipped row scores the take as the detector does.
    take = takes[0]
    expected = metrics.evaluate(get_segmenter("default")().fit_predict(take.take).cuts,
                                take.truth, fps=take.take.fps)
    cells = lines[2][30:].split()
    assert float(cells[3]) == pytest.approx(expected["f1@1s"], abs=5e-4)
    assert float(cells[4]) == pytest.approx(expected["edits_per_cut"], abs=5e-3)
    assert checks.tempo_check([]) == "tempo: no labelled take"


def _figures(line):
    """The seconds of a placement-bound line, in order."""
    return [float(word) for word in line.replace(",", " ").split()
            if word.replace(".", "").isdigit() and "." in word]


def test_the_placement_bound_scores_the_cuts_as_placed_and_what_oracles_could_pick():
    takes = [_Labelled(1), _Labelled(2), _Labelled(3, kind="channels")]
    lines = checks.placement_bound_check(_read(takes)).splitlines()
    assert lines[0].startswith("placement bound")
    assert lines[1].split()[0] == "full-skeleton" and "(2 takes)" in lines[1]
    assert lines[2].split()[0] == "four-channel" and "(1 take)" in lines[2]
    # "as placed" is the bench's median placement error of the shipped cuts.
    errors = [metrics.median_error_s(get_segmenter("default")().fit_predict(t.take).cuts,
                                     t.truth, fps=t.take.fps) for t in takes[:2]]
    placed, best, turning, gap = _figures(lines[1])
    assert placed == pytest.approx(np.mean(errors), abs=5e-4)
    # The placed cut is one of the five estimates, so the best of them is no further off.
    assert best <= placed
    assert 0 < gap < 2
    assert checks.placement_bound_check([]) == \
        "placement bound: no labelled take with a matched cut"
