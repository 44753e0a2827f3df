"""Segment descriptors and motion similarity: invariances, the DTW distance against a
plain oracle, and nearest-neighbour search on the labelled CMU takes and, for points of no
known marker set, on the labelled vMCI takes."""

import json
from collections import Counter
from functools import cache

import numpy as np
import pytest
from numpy.testing import assert_allclose

import motionlib
from motionlib.errors import InputError
from motionlib.similarity import (
    N_POINT_FEATURES,
    PROFILE_ROWS,
    body_scale,
    dtw_distance,
    dtw_distances,
    point_descriptor,
    point_scale,
    rank_similar,
    resample,
    seen_points,
    segment_descriptor,
)
from motionlib.synth import generate
from tests.motionlib.conftest import DATA, cmu_file
from tests.motionlib.points_data import points_file


@pytest.fixture(scope="module")
def synth_take():
    take, segments = generate(seed=3, fps=120.0, duration=20.0)
    return take, motionlib.forward_kinematics(take), motionlib.canonical_indices(take)


def turned(positions, degrees, shift):
    """Positions turned about the vertical axis and moved across the floor."""
    t = np.deg2rad(degrees)
    r = np.array([[np.cos(t), 0, np.sin(t)], [0, 1, 0], [-np.sin(t), 0, np.cos(t)]])
    return positions @ r.T + np.asarray(shift)


def test_it_ignores_where_the_actor_stands_and_which_way_they_face(synth_take):
    take, positions, joints = synth_take
    a = segment_descriptor(positions, joints, 200, 500, fps=take.fps)
    b = segment_descriptor(turned(positions, 137.0, [3.0, 0.0, -7.5]), joints, 200, 500, fps=take.fps)
    assert_allclose(a, b, atol=1e-4)


def test_it_ignores_the_size_of_the_actor(synth_take):
    take, positions, joints = synth_take
    a = segment_descriptor(positions, joints, 200, 500, fps=take.fps)
    b = segment_descriptor(positions * 2.54, joints, 200, 500, fps=take.fps)
    assert_allclose(a, b, atol=1e-4)


def test_it_rejects_a_segment_outside_the_take(synth_take):
    take, positions, joints = synth_take
    with pytest.raises(ValueError, match=r"segment \[500, 99999\) is empty or outside"):
        segment_descriptor(positions, joints, 500, 99999, fps=take.fps)


def test_it_resamples_linearly_keeping_both_ends():
    x = np.array([[0.0], [1.0], [4.0]])
    assert_allclose(resample(x, 5)[:, 0], [0.0, 0.5, 1.0, 2.5, 4.0])
    assert_allclose(resample(np.array([[2.0, 3.0]]), 3), [[2.0, 3.0]] * 3)


def slow_dtw(a, b):
    """Textbook DTW by full recursion table, no band."""
    n, m = len(a), len(b)
    acc = np.full((n + 1, m + 1), np.inf)
    acc[0, 0] = 0
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            d = np.linalg.norm(a[i - 1] - b[j - 1])
            acc[i, j] = d + min(acc[i - 1, j - 1], acc[i - 1, j], acc[i, j - 1])
    return acc[n, m] / (n + m)


def test_it_computes_dtw_like_the_textbook_recursion_when_the_band_is_wide():
    rng = np.random.default_rng(1)
    a, b = rng.normal(size=(12, 3)), rng.normal(size=(9, 3))
    assert dtw_distance(a, b, band=1.0) == pytest.approx(slow_dtw(a, b))


@pytest.mark.parametrize("n, m, band", [(32, 32, 0.25), (12, 9, 0.25), (9, 12, 1.0), (5, 20, 0.1)])
def test_it_computes_a_batch_of_dtw_distances_as_one_at_a_time(n, m, band):
    rng = np.random.default_rng(n + m)
    a, bs = rng.normal(size=(n, 4)), rng.normal(size=(6, m, 4))
    expected = [dtw_distance(a, b, band=band) for b in bs]
    assert dtw_distances(a, bs, band=band).tolist() == pytest.approx(expected, rel=1e-12)


def test_it_names_descriptors_of_different_widths():
    with pytest.raises(InputError, match="dtw: expected"):
        dtw_distances(np.zeros((4, 3)), np.zeros((2, 4, 5)))


def test_it_warps_away_a_change_of_tempo():
    t = np.linspace(0, 1, 40)
    a = np.sin(2 * np.pi * t)[:, None]
    b = np.sin(2 * np.pi * t**1.3)[:, None]
    assert dtw_distance(a, a) == 0.0
    assert dtw_distance(a, b) < np.abs(a - b).sum() / 80


def test_it_ranks_the_library_by_distance_and_validates_shapes():
    rng = np.random.default_rng(2)
    query = rng.normal(size=(PROFILE_ROWS + 8, 4))
    library = np.stack([query + s for s in (3.0, 0.0, 1.0, 2.0)])
    indices, distances = rank_similar(query, library, k=3)
    assert indices.tolist() == [1, 2, 3]
    assert distances[0] == 0.0 and np.all(np.diff(distances) > 0)
    with pytest.raises(ValueError, match="library: expected"):
        rank_similar(query, library[:, :5], k=3)
    with pytest.raises(ValueError, match="k: must be at least 1, got 0"):
        rank_similar(query, library, k=0)


@cache
def labelled_clips(seq, clip_frames=120):
    """Consecutive 1 s clips inside each human-labelled action of a mocap6 take."""
    take = motionlib.read(cmu_file("amc", f"{seq}.amc"), asf=cmu_file("asf", "13.asf"))
    positions = motionlib.forward_kinematics(take)
    joints = motionlib.canonical_indices(take)
    scale = body_scale(positions, joints)
    rows = (DATA / "labels" / "mocap6" / "segments" / f"{seq}.csv").read_text().splitlines()[1:]
    names, descriptors = [], []
    for row in rows:
        _, _, first, last, _, action = row.split(",")
        # Skip half a second at each end: the labels mark 10 fps blocks, not exact cuts.
        for start in range(int(first) - 1 + 60, int(last) - 60 - clip_frames, clip_frames):
            names.append(action)
            descriptors.append(segment_descriptor(positions, joints, start, start + clip_frames,
                                                  fps=take.fps, scale=scale))
    return names, np.stack(descriptors)


@pytest.mark.slow
@pytest.mark.parametrize("action", ["Squat", "Twist"])
def test_it_finds_the_same_action_nearest_within_cmu_13_29(action):
    names, library = labelled_clips("13_29")
    query = names.index(action)
    others = [i for i in range(len(names)) if i != query]
    indices, _ = rank_similar(library[query], library[others], k=3)
    assert [names[others[i]] for i in indices] == [action] * 3


@pytest.mark.slow
def test_it_names_the_right_action_for_most_clips_of_13_29_leaving_each_one_out():
    # Measured 26 of 29 (a squat clip at a pause and two one-hand toe touches miss).
    names, library = labelled_clips("13_29")
    hits = 0
    for query in range(len(names)):
        others = [i for i in range(len(names)) if i != query]
        indices, _ = rank_similar(library[query], library[others], k=1)
        hits += names[others[indices[0]]] == names[query]
    assert hits / len(names) >= 0.85


@pytest.mark.slow
@pytest.mark.parametrize("action", ["Squat", "KneeRaise", "Twist"])
def test_it_finds_the_same_action_in_another_take_of_the_same_actor(action):
    # Every clip of the action in 13_30, searched against the 13_29 library: the nearest
    # clip and most of the three nearest are that action.
    names, library = labelled_clips("13_29")
    query_names, queries = labelled_clips("13_30")
    for q in [i for i, name in enumerate(query_names) if name == action]:
        indices, _ = rank_similar(queries[q], library, k=3)
        found = [names[i] for i in indices]
        assert found[0] == action and found.count(action) >= 2, found


@pytest.fixture(scope="module")
def vmci_run():
    take = motionlib.read(points_file("vmci", "subject1_run1.tsv"))
    return take, seen_points(take.positions)


def test_a_point_descriptor_is_as_wide_as_a_body_descriptor(synth_take, vmci_run):
    take, positions, joints = synth_take
    body = segment_descriptor(positions, joints, 0, 100, fps=take.fps)
    points = point_descriptor(vmci_run[1], 0, 100, fps=60.0)
    assert points.shape == body.shape == (PROFILE_ROWS + 32, N_POINT_FEATURES)


def test_a_point_descriptor_ignores_placement_heading_unit_and_point_order(vmci_run):
    _, points = vmci_run
    a = point_descriptor(points, 100, 300, fps=60.0)
    moved = turned(points, 61.0, [800.0, 0.0, -2500.0])[:, ::-1] / 1000.0
    assert_allclose(a, point_descriptor(moved, 100, 300, fps=60.0), atol=1e-4)


def test_seen_points_closes_gaps_and_leaves_out_points_never_seen():
    points = np.zeros((4, 3, 3))
    points[:, 1] = [[0, 0, 0], [np.nan] * 3, [np.nan] * 3, [3, 3, 3]]
    points[:, 2] = np.nan
    points[:, 0] = 5.0
    assert_allclose(seen_points(points)[:, 1, 0], [0, 1, 2, 3])
    assert seen_points(points).shape == (4, 2, 3)


def test_a_point_descriptor_needs_two_points():
    with pytest.raises(ValueError, match=r"1 point\(s\) seen in the take; distances need at least 2"):
        seen_points(np.ones((5, 1, 3)))


def test_point_descriptors_name_the_action_of_the_other_subjects_vmci_segments():
    """vMCI pick-and-place, top-level labels (7 actions): each segment of subject 2 is
    named by the 5 nearest of subject 1's, and the other way round."""
    items = []
    for path in sorted(points_file("vmci", "subject1_run1.tsv").parent.glob("*.tsv")):
        take = motionlib.read(path)
        points = seen_points(take.positions)
        scale = point_scale(points)
        labels = json.loads(path.with_name(f"{path.stem}_manually_segmented.json").read_text())
        for row in labels:
            start, stop = (row[k] - take.first_number for k in ("start index", "end index"))
            if not row["label"].endswith("_part") and stop > start:
                items.append((path.stem.split("_")[0], row["label"],
                              point_descriptor(points, start, stop, fps=take.fps, scale=scale)))
    right = 0
    for subject, label, descriptor in items:
        others = [(name, d) for s, name, d in items if s != subject]
        order, distances = rank_similar(descriptor, np.stack([d for _, d in others]), k=5)
        votes = Counter()
        for i, d in zip(order, distances, strict=True):
            votes[others[i][0]] += 1.0 / (d * d + 1e-9)
        right += votes.most_common(1)[0][0] == label
    assert right >= 0.75 * len(items), (right, len(items))
