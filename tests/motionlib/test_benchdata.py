import pytest

from motionlib import benchdata

DATA = benchdata.data_dir()
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"benchmark data not found at {DATA}")


def test_it_turns_mocap6_segment_starts_into_0_based_cuts(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text(
        "start_block,end_block,start_frame,end_frame,label_id,action_name\n"
        "1,18,1,216,1,JumpJack\n19,67,217,804,6,Twist\n68,70,805,840,4,KneeRaise\n"
    )
    assert benchdata.mocap6_truth(path)[:, 1].tolist() == [216, 804]
    assert benchdata.mocap6_truth(path, frame_offset=1)[:, 1].tolist() == [217, 805]


def test_it_names_file_line_and_value_of_a_bad_label(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("start_frame,end_frame\n1,216\nabc,804\n")
    with pytest.raises(benchdata.LabelError, match=r"s\.csv: line 3: start_frame .*'abc'"):
        benchdata.mocap6_truth(path)


def test_it_names_a_missing_column(tmp_path):
    path = tmp_path / "k.csv"
    path.write_text("segment,label,end_lo,end_hi\n1,walk,1,2\n")
    with pytest.raises(benchdata.LabelError, match=r"k\.csv: line 1: missing column 'end_mid'"):
        benchdata.kruger_truth(path)


def test_it_reads_transition_windows_and_drops_the_trial_length(tmp_path):
    path = tmp_path / "k.csv"
    path.write_text(
        "segment,label,end_lo,end_mid,end_hi\n1,walk,500,550,600\n2,jump,3881,3840,4000\n"
        "3,walk,4579,4579,4579\n"
    )
    assert benchdata.kruger_truth(path).tolist()[0] == [500, 550, 600]


def test_it_reads_a_best_estimate_outside_its_window_as_the_window_middle(tmp_path):
    path = tmp_path / "k.csv"
    path.write_text(
        "segment,label,end_lo,end_mid,end_hi\n1,walk,3881,3840,4000\n2,jump,1540,1685,1628\n"
        "3,walk,4579,4579,4579\n"
    )
    assert benchdata.kruger_truth(path).tolist() == [[3881, 3940, 4000], [1540, 1584, 1628]]


@needs_data
def test_it_lists_the_three_labelled_takes_with_their_cuts():
    takes = {t.name: t for t in benchdata.labelled_takes()}
    assert list(takes) == ["13_29", "13_30", "86_01"]
    assert takes["13_30"].truth[:, 1].tolist() == [216, 804, 1416, 1932]
    assert takes["13_29"].truth[:, 1].tolist() == [469, 1213, 1921, 2701, 3805]  # BVH frames
    assert takes["86_01"].truth[0].tolist() == [500, 550, 600]
    assert all(t.path.is_file() for t in takes.values())
