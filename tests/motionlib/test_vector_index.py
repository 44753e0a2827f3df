"""The inverted-file vector index: exact when it scans everything, close to exact when it
scans a share, keeps its keys through changes, and refuses damaged files."""

import numpy as np
import pytest

from motionlib.vector_index import IvfIndex, assign, train_centroids


def clustered(n=3000, d=12, centres=40, seed=0):
    rng = np.random.default_rng(seed)
    base = rng.normal(size=(centres, d)) * 3
    return (base[rng.integers(centres, size=n)] + rng.normal(size=(n, d))).astype(np.float32)


def brute(vectors, ids, query, count):
    d = ((vectors.astype(np.float16).astype(np.float32) - query) ** 2).sum(axis=1)
    return ids[np.argsort(d, kind="stable")[:count]]


def test_it_finds_the_exact_neighbours_when_it_scans_every_list():
    x = clustered()
    ids = np.arange(10, 10 + len(x))
    index = IvfIndex.build(ids, x, n_lists=30)
    for q in x[:20]:
        found, _ = index.search(q, 15, probe_share=1.0)
        assert set(found) == set(brute(x, ids, q, 15))


def test_it_finds_most_neighbours_scanning_a_tenth():
    x = clustered()
    ids = np.arange(len(x))
    index = IvfIndex.build(ids, x, n_lists=60)
    recall = [len(set(index.search(q, 10, probe_share=0.1)[0]) & set(brute(x, ids, q, 10))) / 10
              for q in x[::100]]
    assert np.mean(recall) >= 0.9


def test_it_returns_neighbours_nearest_first_with_their_distances():
    x = clustered(n=500)
    index = IvfIndex.build(np.arange(500), x, n_lists=5)
    found, d = index.search(x[3], 8, probe_share=1.0)
    assert found[0] == 3 and d[0] == pytest.approx(0.0, abs=1e-3)
    assert np.all(np.diff(d) >= 0)


def test_it_removes_and_adds_keys_without_retraining():
    x = clustered(n=1000)
    index = IvfIndex.build(np.arange(1000), x, n_lists=10)
    extra = clustered(n=50, seed=1)
    changed = index.changed(np.arange(0, 1000, 2), np.arange(5000, 5050), extra)
    assert sorted(changed.ids.tolist()) == list(range(1, 1000, 2)) + list(range(5000, 5050))
    assert np.array_equal(changed.centroids, index.centroids)
    found, _ = changed.search(extra[7], 1, probe_share=1.0)
    assert found.tolist() == [5007]


def test_it_reads_back_what_it_saved_as_a_memory_map(tmp_path):
    x = clustered(n=800)
    index = IvfIndex.build(np.arange(800), x, n_lists=8)
    index.save(tmp_path / "ix")
    opened = IvfIndex.open(tmp_path / "ix")
    assert isinstance(opened.vectors, np.memmap)
    assert np.array_equal(opened.search(x[1], 5)[0], index.search(x[1], 5)[0])


def test_it_names_the_damaged_file(tmp_path):
    IvfIndex.build(np.arange(800), clustered(n=800), n_lists=8).save(tmp_path / "ix")
    path = tmp_path / "ix" / "vectors.npy"
    path.write_bytes(path.read_bytes()[:1000])
    with pytest.raises(ValueError, match="vectors.npy"):
        IvfIndex.open(tmp_path / "ix")


def test_it_keeps_every_centre_owning_points():
    x = clustered(n=400, centres=4)
    centres = train_centroids(x, 20, seed=3)
    assert len(np.unique(assign(x, centres))) == 20


def test_it_refuses_more_lists_than_vectors():
    with pytest.raises(ValueError, match="n_lists"):
        train_centroids(clustered(n=10), 11)
