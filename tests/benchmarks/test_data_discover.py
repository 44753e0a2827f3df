"""Finding every labelled take in the shared data layout, whatever the takes are called."""

import numpy as np
import pytest

from benchmarks.quality import bench, cli, data, tuning
from motionlib import shared_data, synth, write_bvh
from motionlib.segmenters.default import Default

SEGMENTS = "start_block,end_block,start_frame,end_frame,label_id,action_name\n"
KRUGER = "segment,label,end_lo,end_mid,end_hi\n"


@pytest.fixture(scope="module")
def layout(tmp_path_factory):
    """A data folder with a BVH take, a four-channel take and the odd ones out."""
    root = tmp_path_factory.mktemp("data")
    for folder in ("cmu/bvh", "cmu/amc", "cmu/channels4d", "labels/mocap6/segments",
                   "labels/cmu86_kruger2017"):
        (root / folder).mkdir(parents=True)
    take, _ = synth.generate(seed=1, fps=120.0, duration=12.0)
    write_bvh(take, root / "cmu/bvh/77_05.bvh")
    (root / "labels/mocap6/segments/77_05.csv").write_text(
        SEGMENTS + f"1,50,1,600,1,JumpJack\n51,120,601,{take.n_frames},2,Jog\n")
    (root / "labels/mocap6/segments/77_09.csv").write_text(SEGMENTS + "1,9,1,100,1,Jog\n")
    rows = np.random.default_rng(0).normal(size=(900, 4))
    np.savetxt(root / "cmu/channels4d/91_02.4d.txt", rows, fmt="%.4f")
    (root / "labels/cmu86_kruger2017/91_02.csv").write_text(
        KRUGER + "1,walk,380,400,420\n2,jump,900,900,900\n")
    (root / "cmu/amc/12_34.amc").write_text(":FULLY-SPECIFIED\n:DEGREES\n")
    return root


def test_it_finds_labelled_takes_by_their_files_not_their_names(layout):
    takes, _ = data.discover(layout)
    assert [(t.name, t.kind, t.source) for t in takes] == [
        ("77_05", "skeleton", "mocap6"), ("91_02", "channels", "kruger2017")]


def test_it_says_which_files_it_skipped_and_why(layout):
    _, skipped = data.discover(layout)
    assert skipped == ["skipped labels/mocap6/segments/77_09.csv: labels but no motion",
                       "skipped cmu/amc/12_34.amc: motion but no labels"]


def test_it_shifts_mocap6_cuts_by_the_lines_a_bvh_adds_before_the_motion(layout):
    take = data.discover(layout)[0][0]
    # The BVH has as many frames as the labels: no added T-pose line, no shift.
    assert take.truth[:, 1].tolist() == [600]


def test_it_lists_the_full_skeleton_takes_without_labels(layout):
    # The AMC has no ASF of its subject, so it cannot be read; the labelled BVH is listed
    # by discover instead.
    assert data.unlabelled_motion(layout) == []
    (layout / "cmu/asf").mkdir(exist_ok=True)
    (layout / "cmu/asf/12.asf").write_text(":version 1.10\n")
    (layout / "cmu/bvh/12_34.bvh").write_text("")
    try:
        assert data.unlabelled_motion(layout) == [
            (layout / "cmu/amc/12_34.amc", layout / "cmu/asf/12.asf")]  # AMC first
    finally:
        (layout / "cmu/asf/12.asf").unlink()
        (layout / "cmu/bvh/12_34.bvh").unlink()


def test_it_reads_a_four_channel_take_as_angles_at_the_cmu_rate(layout):
    take = data.discover(layout)[0][1]
    read = take.read()
    assert (read.n_frames, read.channels.shape[1], read.fps) == (900, 4, 120.0)
    assert take.truth.tolist() == [[380, 400, 420]]


def test_it_names_the_line_of_a_bad_four_channel_row(tmp_path):
    path = tmp_path / "x.4d.txt"
    path.write_text("1 2 3 4\n1 2 x 4\n")
    with pytest.raises(data.LabelError, match=r"x\.4d\.txt: line 2: not numbers"):
        data.read_channels(path)


class View:
    """A scored view of a capture, as tuning.Selection sees it."""

    def __init__(self, name, source="mocap6", pool=False):
        self.labelled = type("L", (), {"name": name, "source": source})()
        self.key, self.pool = name, pool


def test_it_chooses_settings_without_the_take_scored_or_its_other_views():
    cache = [View("a"), View("a"), View("b")]
    good = {"f1@1s": 1.0, "edits_per_cut": 0.0}
    bad = {"f1@1s": 0.0, "edits_per_cut": 1.0}
    # Choice 0 is best on the two views of "a", choice 1 on "b".
    selection = tuning.Selection([{"c": 0}, {"c": 1}], cache,
                                 [[good, good, bad], [bad, bad, good]])
    chosen = [choice["c"] for choice, _ in selection.leave_one_out()]
    assert chosen == [1, 1, 0]


def test_it_scores_choosing_by_f1_first_and_by_edits_first_leave_one_take_out():
    cache = [View("a"), View("b"), View("c")]
    # Choice 0 finds every cut with many false ones, choice 1 fewer cuts and fewer edits:
    # F1 first picks 0, edits first picks 1, on whichever two takes the choice is made.
    many = {"f1@1s": 0.9, "edits_per_cut": 0.6}
    few = {"f1@1s": 0.8, "edits_per_cut": 0.4}
    selection = tuning.Selection([{"c": 0}, {"c": 1}], cache, [[many] * 3, [few] * 3])
    assert [c["c"] for c, _ in selection.leave_one_out()] == [0, 0, 0]
    assert [c["c"] for c, _ in selection.leave_one_out(tuning.edits_objective)] == [1, 1, 1]
    (first, f1, edits), (other, f1_e, edits_e) = tuning.objectives(selection)
    assert (first, other) == ("F1@1s first", "edits first")
    assert np.allclose([f1, edits, f1_e, edits_e], [0.9, 0.6, 0.8, 0.4])


def test_it_chooses_settings_on_the_other_label_sources_only_to_show_their_transfer():
    cache = [*(View(name, "mocap6") for name in "abcd"), View("e", "kruger2017"),
             View("f", "kruger2017", pool=True)]
    good = {"f1@1s": 1.0, "edits_per_cut": 0.0, "median_error_s": 0.1}
    bad = {"f1@1s": 0.5, "edits_per_cut": 1.0, "median_error_s": 0.5}
    # Choice 0 is best on the four mocap6 takes, choice 1 on the two kruger2017 ones.
    selection = tuning.Selection([{"c": 0}, {"c": 1}], cache,
                                 [[good] * 4 + [bad] * 2, [bad] * 4 + [good] * 2])
    assert [c["c"] for c, _ in selection.leave_source_out()] == [1, 1, 1, 1, 0, 0]
    # Leave-one-take-out chooses on the other mocap6 takes too, so the majority wins.
    assert [c["c"] for c, _ in selection.leave_one_out()] == [0] * 6
    (m, m_n, m_other, m_loo), (k, k_n, k_other, k_loo) = tuning.by_source(selection)
    assert (m, m_n, k, k_n) == ("mocap6", 4, "kruger2017", 1)  # a pool take is not scored
    assert m_other == {"f1@1s": 0.5, "edits_per_cut": 1.0, "median_error_s": 0.5}
    assert m_loo == {"f1@1s": 1.0, "edits_per_cut": 0.0, "median_error_s": 0.1}
    assert k_other == k_loo == {"f1@1s": 0.5, "edits_per_cut": 1.0, "median_error_s": 0.5}
    single = tuning.Selection([{"c": 0}], cache[:2], [[good, good]])
    assert single.leave_source_out() == [None, None]  # no other source to choose on


def test_it_prints_leave_one_take_out_rows_beside_the_others(layout, capsys):

    assert bench.main(layout, ["bone_angle"], loo=True, pool=[]) == 0
    out = capsys.readouterr().out
    assert "Rows ending in /loo were scored leave-one-take-out" in out
    for row in ("default/loo", "adapted/loo", "ruptures/loo"):
        assert out.count(f"\n{row} ") == 2 + 3  # two takes, three mean tables
    assert "mean over 1 full-skeleton takes" in out and "mean over 2 labelled takes" in out
    assert "out of sample (leave-one-take-out)" in out
    assert "objective       F1@1s first" in out and "objective       edits first" in out
    assert "(leave-one-source-out)" in out


def test_it_keeps_the_shipped_value_first_among_the_tried_options():
    grid = tuning.tried_grid()
    for key, values in tuning.TRIED.items():
        assert grid[key][0] == tuning.Tried.params[key].default
        assert set(values) <= set(grid[key])
    assert {k: v for k, v in grid.items() if k not in tuning.TRIED} == tuning.GRID


def test_it_finds_the_shipped_grid_inside_the_tried_one():
    choices = [{"threshold": 0.1, "short_activity": 0.0}, {"threshold": 0.1, "short_activity": 4.0},
               {"threshold": 0.2}]
    rows = [[{"f1@1s": 0.0, "edits_per_cut": 0.0}]] * 3
    shipped = tuning.Selection(choices, [None], rows).subset(short_activity=0.0)
    # A choice that does not set it has the shipped value.
    assert shipped.choices == [choices[0], choices[2]]


def test_the_shipped_choices_inside_the_tried_grid_are_settings_of_the_shipped_detector():
    choices = [{"threshold": 0.1, "short_activity": 0.0, "short_uniformity": 0.0, "tempo": False},
               {"threshold": 0.1, "short_activity": 4.0, "short_uniformity": 0.0, "tempo": False}]
    rows = [[{"f1@1s": 0.0, "edits_per_cut": 0.0}]] * 2
    shipped = tuning.Selection(choices, [None], rows).shipped()
    assert shipped.choices == [{"threshold": 0.1}]
    assert tuning.detector(shipped.choices[0]) is Default
    assert tuning.detector(choices[1]) is tuning.Tried


def test_it_makes_no_leave_one_take_out_choice_for_a_take_with_no_other_capture():
    good = {"f1@1s": 1.0, "edits_per_cut": 0.0}
    selection = tuning.Selection([{"c": 0}, {"c": 1}], [View("a"), View("a")],
                                 [[good, good], [good, good]])
    assert selection.leave_one_out() == [None, None]
    assert all(np.isnan(f1) and np.isnan(edits)
               for _, _, f1, edits in tuning.out_of_sample(selection, {"c": (0, 1)}))


def _mocap6_folder(root, seeds, names):
    """A data folder of synthetic BVH takes labelled in the mocap6 layout."""
    for folder in ("cmu/bvh", "labels/mocap6/segments"):
        (root / folder).mkdir(parents=True, exist_ok=True)
    for seed, name in zip(seeds, names, strict=True):
        take, segments = synth.generate(seed=seed, fps=60.0, duration=24.0)
        write_bvh(take, root / f"cmu/bvh/{name}.bvh")
        rows = "".join(f"{i + 1},{i + 1},{start + 1},{stop},1,{label}\n"
                       for i, (start, stop, label) in enumerate(segments))
        (root / f"labels/mocap6/segments/{name}.csv").write_text(SEGMENTS + rows)
    return root


def test_leave_one_take_out_also_chooses_on_and_learns_from_the_pool_without_scoring_it(
        tmp_path):

    scored = _mocap6_folder(tmp_path / "new", [3], ["40_01"])
    # The pool holds two other takes and one with the scored take's name and kind.
    pool = _mocap6_folder(tmp_path / "pool", [4, 5, 6], ["40_02", "40_03", "40_01"])
    alone = bench.run(scored, ["default"], loo=True)
    assert np.isnan(alone["40_01"]["default/loo"]["f1@1s"])  # nothing else to choose on
    assert np.isnan(alone["40_01"]["adapted/loo"]["f1@1s"])  # nothing to learn from

    selections = []
    results = bench.run(scored, ["default"], loo=True, pool=[pool],
                                selection_out=selections)
    assert list(results) == ["40_01"]  # the pool is not scored
    cache = selections[0].cache
    assert [(c.labelled.name, c.pool) for c in cache] == [
        ("40_01", False), ("40_02", True), ("40_03", True)]
    # The scored take's settings are the ones chosen on the two pool takes.
    on_pool = tuning.select(cache[1:]).chosen()
    expected = bench.metrics.evaluate(
        cache[0].cuts(on_pool), cache[0].labelled.truth, fps=cache[0].take.fps)
    row = results["40_01"]["default/loo"]
    assert (row["f1@1s"], row["edits_per_cut"]) == (expected["f1@1s"],
                                                     expected["edits_per_cut"])
    assert not np.isnan(results["40_01"]["adapted/loo"]["f1@1s"])
    assert not np.isnan(results["40_01"]["ruptures/loo"]["f1@1s"])


def test_the_cli_says_so_when_a_pool_folder_is_missing(layout, tmp_path, capsys):

    assert bench.main(layout, ["bone_angle"], loo=True,
                              pool=[tmp_path / "nowhere"]) == 2
    assert f"benchmark data folder not found: {tmp_path / 'nowhere'}" in capsys.readouterr().err


def test_the_default_pool_is_the_shared_data_wherever_it_is_set_and_never_the_folder_scored(
        tmp_path, monkeypatch):

    copy, scored = tmp_path / "shared-copy", tmp_path / "new"
    copy.mkdir()
    scored.mkdir()
    monkeypatch.setenv("CUTROOM_BENCH_DATA", str(copy))
    assert bench.default_pool(scored) == [copy.resolve()]
    # Scoring the shared data itself: the pool is the shared folder beside the repository,
    # if it is there and another folder, else nothing.
    beside = shared_data.DEFAULT_DATA_DIR.resolve()
    assert bench.default_pool(copy) == ([beside] if beside.is_dir() else [])
    monkeypatch.setenv("CUTROOM_BENCH_DATA", str(tmp_path / "missing"))
    assert bench.default_pool(scored) == ([beside] if beside.is_dir() else [])
    assert bench.default_pool(beside) == []


def test_it_skips_a_take_whose_labels_lie_outside_its_motion_naming_the_label_file(
        tmp_path, capsys):

    for folder in ("cmu/channels4d", "labels/cmu86_kruger2017"):
        (tmp_path / folder).mkdir(parents=True)
    np.savetxt(tmp_path / "cmu/channels4d/91_02.4d.txt",
               np.random.default_rng(0).normal(size=(900, 4)), fmt="%.4f")
    labels = tmp_path / "labels/cmu86_kruger2017/91_02.csv"
    # Labels of a longer take: the second cut is past the 900 frames read.
    labels.write_text(KRUGER + "1,walk,380,400,420\n2,jog,930,950,970\n3,end,1200,1200,1200\n")
    (take,) = data.discover(tmp_path)[0]
    with pytest.raises(data.LabelError) as error:
        take.read()
    assert str(error.value) == (
        f"{labels}: cut at frame 950 is outside {tmp_path}/cmu/channels4d/91_02.4d.txt "
        f"(900 frames): the labels do not fit this motion")
    # The bench skips the take with that line instead of counting the cut as missed, and
    # goes on with the others (here: a take whose motion cannot be read, skipped too);
    # with nothing left to score it exits 2.
    (tmp_path / "cmu/amc").mkdir()
    (tmp_path / "cmu/asf").mkdir()
    (tmp_path / "cmu/amc/91_03.amc").write_text(":FULLY-SPECIFIED\n:DEGREES\n1\nroot x\n")
    (tmp_path / "cmu/asf/91.asf").write_text(":version 1.10\n")
    (tmp_path / "labels/cmu86_kruger2017/91_03.csv").write_text(KRUGER + "1,a,5,5,5\n")
    assert cli.main(["--data", str(tmp_path), "--method", "bone_angle"]) == 2
    out = capsys.readouterr()
    assert f"skipped 91_02 (91_02.4d.txt): {error.value}\n" in out.out
    assert "skipped 91_03 (91_03.amc): 91.asf:1: missing :root section" in out.out
    assert out.err == f"error: no labelled take to score under {tmp_path} (see the lines above)\n"


def test_it_skips_a_label_file_it_cannot_read_naming_the_row_and_goes_on(tmp_path):
    for folder in ("cmu/channels4d", "cmu/bvh", "labels/cmu86_kruger2017",
                   "labels/mocap6/segments"):
        (tmp_path / folder).mkdir(parents=True)
    write_bvh(synth.generate(seed=1, fps=30.0, duration=4.0)[0], tmp_path / "cmu/bvh/77_05.bvh")
    for name in ("91_02", "91_04"):
        np.savetxt(tmp_path / f"cmu/channels4d/{name}.4d.txt",
                   np.random.default_rng(0).normal(size=(900, 4)), fmt="%.4f")
    kruger = tmp_path / "labels/cmu86_kruger2017"
    (kruger / "91_02.csv").write_text(KRUGER + "1,walk,380,4OO,420\n2,end,900,900,900\n")
    (kruger / "91_04.csv").write_text(KRUGER + "1,walk,380,400,420\n2,end,900,900,900\n")
    (tmp_path / "labels/mocap6/segments/77_05.csv").write_bytes(
        SEGMENTS.encode() + b"1,50,1,600,1,Jump\xff\n")
    takes, skipped = data.discover(tmp_path)
    assert [t.name for t in takes] == ["91_04"]
    assert skipped[0].startswith("skipped labels/mocap6/segments/77_05.csv: cannot read the "
                                 "labels: 'utf-8' codec can't decode byte 0xff")
    assert skipped[1:] == ["skipped labels/cmu86_kruger2017/91_02.csv: line 2: end_mid is "
                           "not an integer: '4OO'"]


SHARED = shared_data.data_dir()


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"CMU benchmark data not found at {SHARED}")
def test_the_original_mocap6_block_files_give_the_cuts_of_their_segments_csv():
    for name in ("13_29", "13_30"):
        blocks = data.mocap6_block_truth(SHARED / f"labels/mocap6/{name}.txt")
        runs = data.mocap6_truth(SHARED / f"labels/mocap6/segments/{name}.csv")
        assert blocks.tolist() == runs.tolist() and len(runs) >= 4


@pytest.mark.skipif(not SHARED.is_dir(), reason=f"CMU benchmark data not found at {SHARED}")
def test_a_mocap6_take_with_only_its_block_file_is_found_with_its_amc(tmp_path):
    for folder in ("cmu/amc", "cmu/asf", "cmu/bvh", "labels/mocap6"):
        (tmp_path / folder).mkdir(parents=True)
    (tmp_path / "cmu/amc/13_30.amc").symlink_to(SHARED / "cmu/amc/13_30.amc")
    (tmp_path / "cmu/asf/13.asf").symlink_to(SHARED / "cmu/asf/13.asf")
    (tmp_path / "labels/mocap6/13_30.txt").symlink_to(SHARED / "labels/mocap6/13_30.txt")
    (tmp_path / "cmu/bvh/13_31.bvh").write_text("HIERARCHY\n")
    (tmp_path / "labels/mocap6/13_31.txt").write_text("1 1 2 2\n")
    (tmp_path / "cmu/amc/13_32.amc").symlink_to(SHARED / "cmu/amc/13_30.amc")
    (tmp_path / "labels/mocap6/13_32.txt").write_text("1 1 x 2\n")
    takes, skipped = data.discover(tmp_path)
    assert [(t.name, t.source, t.path.name) for t in takes] == [("13_30", "mocap6", "13_30.amc")]
    expected = data.mocap6_truth(SHARED / "labels/mocap6/segments/13_30.csv")
    assert takes[0].truth.tolist() == expected.tolist()
    assert takes[0].read().n_frames == 2465
    assert skipped == [
        "skipped labels/mocap6/13_31.txt: block labels count AMC frames; add the AMC and its "
        "ASF, or segments/13_31.csv",
        "skipped labels/mocap6/13_32.txt: block 3: activity id is not an integer: 'x'"]
