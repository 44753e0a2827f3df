"""The point-set benchmark's true cuts, from the label files of the real point takes."""

import numpy as np
import pytest

from benchmarks.quality import points as points_quality
from tests.motionlib.points_data import POINTS, points_file


@pytest.fixture(scope="module")
def data():
    points_file("hdm05", "labels.csv")
    return POINTS.parent


def test_hdm05_cuts_are_the_starts_and_ends_of_its_intervals(data):
    (item,) = points_quality.hdm05(data).takes
    assert item.truth[:, 1].tolist() == [632, 786, 1189, 1704, 1770, 4089, 4849, 4978, 5554,
                                         5784]


def test_utkinect_cuts_are_windows_between_consecutive_actions(data):
    item = next(t for t in points_quality.utkinect(data).takes if t.name == "s01_e01")
    assert len(item.truth) == 9
    np.testing.assert_array_equal(item.truth[0], [390 - 190, (390 + 572) // 2 - 190, 572 - 190])


def test_vmci_cuts_use_the_finest_segments(data):
    item = next(t for t in points_quality.vmci(data).takes if t.name == "subject1_run1")
    lo_hi = [(lo + 690, hi + 690) for lo, _, hi in item.truth]
    assert lo_hi == [(734, 734), (797, 820), (912, 971), (1027, 1027), (1094, 1094),
                     (1185, 1185), (1289, 1323)]
