import numpy as np
import pytest

from benchmarks.quality import data, variants
from motionlib import shared_data, synth
from motionlib.errors import InputError

DATA = shared_data.data_dir()
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason=f"benchmark data not found at {DATA}")


def test_it_turns_mocap6_segment_starts_into_0_based_cuts(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text(
        "start_block,end_block,start_frame,end_frame,label_id,action_name\n"
        "1,18,1,216,1,JumpJack\n19,67,217,804,6,Twist\n68,70,805,840,4,KneeRaise\n"
    )
    assert data.mocap6_truth(path)[:, 1].tolist() == [216, 804]
    assert data.mocap6_truth(path, frame_offset=1)[:, 1].tolist() == [217, 805]


def test_it_names_file_line_and_value_of_a_bad_label(tmp_path):
    path = tmp_path / "s.csv"
    path.write_text("start_frame,end_frame\n1,216\nabc,804\n")
    with pytest.raises(data.LabelError, match=r"s\.csv: line 3: start_frame .*'abc'"):
        data.mocap6_truth(path)


def test_it_names_a_missing_column(tmp_path):
    path = tmp_path / "k.csv"
    path.write_text("segment,label,end_lo,end_hi\n1,walk,1,2\n")
    with pytest.raises(data.LabelError, match=r"k\.csv: line 1: missing column 'end_mid'"):
        data.kruger_truth(path)


def test_it_reads_transition_windows_and_drops_the_trial_length(tmp_path):
    path = tmp_path / "k.csv"
    path.write_text(
        "segment,label,end_lo,end_mid,end_hi\n1,walk,500,550,600\n2,jump,3881,3840,4000\n"
        "3,walk,4579,4579,4579\n"
    )
    assert data.kruger_truth(path).tolist()[0] == [500, 550, 600]


def test_it_reads_a_best_estimate_outside_its_window_as_the_window_middle(tmp_path):
    path = tmp_path / "k.csv"
    path.write_text(
        "segment,label,end_lo,end_mid,end_hi\n1,walk,3881,3840,4000\n2,jump,1540,1685,1628\n"
        "3,walk,4579,4579,4579\n"
    )
    assert data.kruger_truth(path).tolist() == [[3881, 3940, 4000], [1540, 1584, 1628]]


@needs_data
def test_it_lists_the_three_labelled_takes_with_their_cuts():
    takes = {t.name: t for t in data.labelled_takes()}
    assert list(takes) == ["13_29", "13_30", "86_01"]
    assert takes["13_30"].truth[:, 1].tolist() == [216, 804, 1416, 1932]
    assert takes["13_29"].truth[:, 1].tolist() == [469, 1213, 1921, 2701, 3805]  # BVH frames
    assert takes["86_01"].truth[0].tolist() == [500, 550, 600]
    assert all(t.path.is_file() for t in takes.values())


def _windows(seed=3):
    """A synthetic take and its true cuts as 2 s transition windows."""
    take, segments = synth.generate(seed=seed, fps=60.0, duration=40.0)
    truth = np.repeat(np.asarray([s[0] for s in segments[1:]])[:, None], 3, axis=1)
    truth[:, 0] -= 60
    truth[:, 2] += 60
    return take, truth


def test_a_shortened_take_keeps_the_activity_ends_and_moves_the_later_cuts_back():
    take, truth = _windows()
    start, stop = truth[1, 1], truth[2, 1]
    short, moved = variants.shortened(take, truth, 1, 1.8)
    removed = take.n_frames - short.n_frames
    assert removed == stop - start - 108  # 1.8 s at 60 fps is left
    join = start + 54
    np.testing.assert_array_equal(short.channels[:join], take.channels[:join])
    np.testing.assert_array_equal(short.channels[join:], take.channels[join + removed:])
    np.testing.assert_array_equal(moved[:2, 1], truth[:2, 1])
    np.testing.assert_array_equal(moved[2:, 1], truth[2:, 1] - removed)
    assert moved[2, 1] - moved[1, 1] == 108
    # The windows beside the join stop at it; no other window changes.
    assert moved[1, 2] == join - 1 < truth[1, 2]
    assert moved[2, 0] == join
    np.testing.assert_array_equal(moved[3:], truth[3:] - removed)
    assert short.positions is None and short.skeleton is take.skeleton


def test_an_activity_already_as_short_is_not_shortened_and_a_wrong_index_is_named():
    take, segments = synth.generate(seed=3, fps=60.0, duration=40.0)
    cuts = np.asarray([s[0] for s in segments[1:]])
    truth = np.repeat(cuts[:, None], 3, axis=1)
    length = (cuts[1] - cuts[0]) / take.fps
    assert variants.shortened(take, truth, 0, length) is None
    with pytest.raises(ValueError, match=f"activity {len(cuts) - 1}: .* 0 to {len(cuts) - 2}"):
        variants.shortened(take, truth, len(cuts) - 1, 1.8)


def test_a_take_shortened_throughout_has_every_inner_activity_cut_down_and_its_ends_kept():
    channels = np.arange(1200, dtype=float).reshape(300, 4)
    take = data.ChannelTake(name="t", fps=10.0, channels=channels)
    # Inner activities of 8, 2 and 9 s; the first (3 s) and the last (6 s) are not inner.
    truth = np.repeat(np.asarray([30, 110, 130, 220])[:, None], 3, axis=1)
    short, moved = variants.shortened_throughout(take, truth, 4.0)
    np.testing.assert_array_equal(moved[:, 1], [30, 70, 90, 130])
    assert short.n_frames == 300 - 40 - 50
    np.testing.assert_array_equal(short.channels[:50], channels[:50])  # up to the first join
    np.testing.assert_array_equal(short.channels[-60:], channels[-60:])  # the last activity
    # Nothing longer: the take itself.
    same, kept = variants.shortened_throughout(take, truth, 9.0)
    assert same is take
    np.testing.assert_array_equal(kept, truth)


def test_a_four_channel_take_is_shortened_the_same_way():
    channels = np.arange(1200, dtype=float).reshape(300, 4)
    take = data.ChannelTake(name="t", fps=10.0, channels=channels)
    truth = np.asarray([[100, 100, 100], [250, 250, 250]])
    short, moved = variants.shortened(take, np.vstack([[20, 20, 20], truth]), 1, 5.0)
    assert isinstance(short, data.ChannelTake) and short.n_frames == 200
    np.testing.assert_array_equal(short.channels[125], channels[225])
    np.testing.assert_array_equal(moved[:, 1], [20, 100, 150])


def test_a_take_trimmed_at_its_start_begins_its_first_activity_the_seconds_asked_before_its_cut():
    take, truth = _windows()
    short, moved = variants.trimmed(take, truth, "first", 1.5)
    dropped = truth[0, 1] - 90  # 1.5 s at 60 fps is left before the first cut
    assert short.n_frames == take.n_frames - dropped
    np.testing.assert_array_equal(short.channels, take.channels[dropped:])
    assert moved[0, 1] == 90
    np.testing.assert_array_equal(moved[1:], truth[1:] - dropped)
    assert moved[0, 0] == max(0, truth[0, 0] - dropped)


def test_a_take_trimmed_at_its_end_stops_the_seconds_asked_after_its_last_cut():
    take, truth = _windows()
    short, moved = variants.trimmed(take, truth, "last", 1.8)
    assert short.n_frames == truth[-1, 1] + 108
    np.testing.assert_array_equal(short.channels, take.channels[:short.n_frames])
    np.testing.assert_array_equal(moved[:-1], truth[:-1])
    assert moved[-1, 1] == truth[-1, 1] and moved[-1, 2] <= short.n_frames - 1


def test_an_end_activity_already_as_short_is_not_trimmed_and_a_wrong_side_is_named():
    take, truth = _windows()
    assert variants.trimmed(take, truth, "first", truth[0, 1] / take.fps) is None
    assert variants.trimmed(take, truth, "last", 1000.0) is None
    with pytest.raises(InputError, match="side: expected 'first' or 'last', got 'middle'"):
        variants.trimmed(take, truth, "middle", 1.5)
