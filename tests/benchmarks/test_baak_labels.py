"""Baak / Müller's sparse interval labels of the subject-86 takes as true cuts."""

import numpy as np

from benchmarks.quality.data import baak_takes, baak_truth


def test_it_cuts_at_every_interval_start_and_end_merging_those_half_a_second_apart():
    # 1-based inclusive frames at 120 fps: a move, a turn inside it, a jump 30 frames
    # after the move ends, and a last interval that ends the take.
    spans = [(101, 500), (300, 420), (531, 900), (1000, 1200)]
    truth = baak_truth(spans)
    # 100 | 299, 420 (apart) | 500 and 530 merged | 900 | 999; 1200 is the take's end.
    assert truth.tolist() == [[100, 100, 100], [299, 299, 299], [420, 420, 420],
                              [500, 515, 530], [900, 900, 900], [999, 999, 999]]


def test_it_reads_the_takes_that_have_motion():
    takes = baak_takes()
    assert [t.name for t in takes] == ["86_01", "86_02", "86_03", "86_07", "86_08", "86_11"]
    assert all(t.source == "baak" and len(t.truth) and np.all(np.diff(t.truth[:, 1]) > 0)
               for t in takes)
