"""A bare point descriptor costs memory linear in the points (issue 48, item 1): the
distances between every two of 1,000 points took 500,000 pairs a frame, gigabytes for a
take of a few hundred frames, and killed the worker that computed a reviewer's suggestions."""

import tracemalloc

import numpy as np
from numpy.testing import assert_allclose

from motionlib.similarity import PAIR_POINTS, pair_points, point_descriptor


def cloud(n_points, n_frames=20, seed=0):
    rng = np.random.default_rng(seed)
    drift = np.cumsum(rng.normal(size=(n_frames, 1, 3)), axis=0)
    return rng.normal(size=(1, n_points, 3)) * 300.0 + drift


def peak_bytes(points):
    tracemalloc.start()
    try:
        point_descriptor(points, 0, len(points), fps=60.0)
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def test_ten_times_the_points_takes_about_ten_times_the_memory():
    small, large = peak_bytes(cloud(60)), peak_bytes(cloud(600))
    # Linear: about 10 times; every pair of points: about 100 times.
    assert large < 25 * small, (small, large)


def test_many_points_keep_the_descriptor_independent_of_their_order():
    points = cloud(300, n_frames=40)
    shuffled = points[:, np.random.default_rng(1).permutation(300)]
    assert_allclose(point_descriptor(points, 0, 40, fps=60.0),
                    point_descriptor(shuffled, 0, 40, fps=60.0), atol=1e-5)


def test_up_to_pair_points_every_pair_is_measured():
    centred = cloud(PAIR_POINTS) - cloud(PAIR_POINTS).mean(axis=1, keepdims=True)
    assert list(pair_points(centred)) == list(range(PAIR_POINTS))
    assert len(set(pair_points(cloud(PAIR_POINTS * 5)))) == PAIR_POINTS
