"""The appendable vector index: exact when it scans every list, close to exact when it
scans a few, sees appended and removed keys at the state that counts them and not before,
ignores what a crashed writer left, and names a damaged file."""

import numpy as np
import pytest

from motionlib import vector_index
from motionlib.errors import InputError
from motionlib.vector_index import VectorIndex


def clustered(n=3000, d=12, centres=40, seed=0):
    rng = np.random.default_rng(seed)
    base = rng.normal(size=(centres, d)) * 3
    return (base[rng.integers(centres, size=n)] + rng.normal(size=(n, d))).astype(np.float32)


def brute(vectors, ids, query, count):
    d = ((vectors - query) ** 2).sum(axis=1)
    return ids[np.argsort(d, kind="stable")[:count]]


def built(tmp_path, x, ids=None, n_lists=10):
    ids = np.arange(len(x)) if ids is None else ids
    state = vector_index.build(tmp_path / "index", ids, x, n_lists=n_lists)
    state.pop("lists")
    return tmp_path / "index", state


def test_it_finds_the_exact_neighbours_when_it_scans_every_list(tmp_path):
    x = clustered()
    ids = np.arange(10, 10 + len(x))
    folder, state = built(tmp_path, x, ids, n_lists=30)
    index = VectorIndex.open(folder, state)
    for q in x[:20]:
        found, _ = index.search(q, 15, nprobe=30)
        assert set(found) == set(brute(x, ids, q, 15))


def test_it_finds_most_neighbours_scanning_a_tenth_of_the_lists(tmp_path):
    x = clustered()
    ids = np.arange(len(x))
    folder, state = built(tmp_path, x, n_lists=60)
    index = VectorIndex.open(folder, state)
    recall = [len(set(index.search(q, 10, nprobe=6)[0]) & set(brute(x, ids, q, 10))) / 10
              for q in x[::100]]
    assert np.mean(recall) >= 0.9


def test_it_returns_neighbours_nearest_first_with_their_distances(tmp_path):
    x = clustered(n=500)
    folder, state = built(tmp_path, x, n_lists=5)
    found, d = VectorIndex.open(folder, state).search(x[3], 8, nprobe=5)
    assert found[0] == 3 and d[0] == pytest.approx(0.0, abs=1e-3)
    assert np.all(np.diff(d) >= 0)


def test_it_finds_appended_keys_and_drops_removed_ones(tmp_path):
    x = clustered(n=1000)
    folder, state = built(tmp_path, x)
    extra = clustered(n=50, seed=1)
    state = vector_index.append(folder, state, np.arange(5000, 5050), extra, np.arange(0, 1000, 2))
    index = VectorIndex.open(folder, state)
    assert index.keys().tolist() == list(range(1, 1000, 2)) + list(range(5000, 5050))
    assert index.search(extra[7], 1, nprobe=10)[0].tolist() == [5007]
    assert 4 not in index.search(x[4], 5, nprobe=10)[0]


def test_it_returns_the_stored_vectors_of_what_it_finds(tmp_path):
    x = clustered(n=1000)
    ids = np.arange(100, 1100)
    folder, state = built(tmp_path, x, ids)
    extra = clustered(n=20, seed=5)
    state = vector_index.append(folder, state, np.arange(5000, 5020), extra, [100, 101])
    stored = dict(zip([*ids.tolist(), *range(5000, 5020)], [*x, *extra], strict=True))
    index = VectorIndex.open(folder, state)
    for q, first in ((x[2], 102), (extra[3], 5003)):
        keys, d, vectors = index.search(q, 30, nprobe=10, vectors=True)
        plain, plain_d = index.search(q, 30, nprobe=10)
        assert keys.tolist() == plain.tolist() and np.array_equal(d, plain_d)
        assert 100 not in keys and 101 not in keys
        assert vectors.dtype == np.float32 and vectors.shape == (30, x.shape[1])
        assert all(np.array_equal(v, stored[k]) for k, v in zip(keys.tolist(), vectors, strict=True))
        assert keys[0] == first and np.array_equal(vectors[0], q)


def test_an_append_leaves_the_base_file_as_it_was(tmp_path):
    folder, state = built(tmp_path, clustered(n=1000))
    before = (folder / vector_index.BASE).read_bytes()
    vector_index.append(folder, state, [5000], clustered(n=1, seed=2), [3])
    assert (folder / vector_index.BASE).read_bytes() == before


def test_a_reader_sees_only_the_records_its_state_counts(tmp_path):
    x = clustered(n=1000)
    folder, state = built(tmp_path, x)
    extra = clustered(n=5, seed=3)
    later = vector_index.append(folder, state, np.arange(7000, 7005), extra, [9])
    earlier = VectorIndex.open(folder, state)
    assert earlier.search(extra[0], 1, nprobe=10)[0].tolist() != [7000]
    assert 9 in earlier.keys() and 9 not in earlier.at(later).keys()
    assert earlier.at(later).search(extra[0], 1, nprobe=10)[0].tolist() == [7000]


def test_it_overwrites_what_a_crashed_append_left_past_the_state(tmp_path):
    folder, state = built(tmp_path, clustered(n=1000))
    with open(folder / vector_index.DELTA_IDS, "ab") as fh:
        fh.write(b"\x01\x02\x03")  # half a record, never counted by a state
    vector_index.append(folder, state, [8000], clustered(n=1, seed=4))
    assert np.fromfile(folder / vector_index.DELTA_IDS, dtype="<i8").tolist() == [8000]


def test_it_names_a_file_shorter_than_its_state(tmp_path):
    folder, state = built(tmp_path, clustered(n=800))
    state = vector_index.append(folder, state, [9000], clustered(n=1, seed=5))
    (folder / vector_index.DELTA_VECTORS).write_bytes(b"")
    with pytest.raises(InputError, match="delta_vectors.f32: 0 bytes"):
        VectorIndex.open(folder, state)


def test_it_refuses_more_lists_than_vectors(tmp_path):
    with pytest.raises(InputError, match="n_lists"):
        vector_index.build(tmp_path / "i", np.arange(5), clustered(n=5), n_lists=6)


def test_it_returns_the_payload_of_base_and_appended_keys(tmp_path):
    x = clustered(n=300)
    rows = np.arange(300 * 4, dtype="<f4").reshape(300, 4)
    (tmp_path / "payload").write_bytes(rows.tobytes())
    ids = np.arange(0, 600, 2)
    state = vector_index.build(tmp_path / "index", ids, x, n_lists=3,
                               payload=tmp_path / "payload", payload_width=4)
    state.pop("lists")
    state = vector_index.append(tmp_path / "index", state, [1001], clustered(n=1, seed=6),
                                add_payload=[[7, 7, 7, 7]])
    found, got = VectorIndex.open(tmp_path / "index", state).payload([4, 1001, 5, 9999])
    assert found.tolist() == [True, True, False, False]
    assert got.tolist() == [rows[2].tolist(), [7] * 4, [0] * 4, [0] * 4]


@pytest.mark.parametrize("in_memory", [False, True])
def test_it_returns_payload_rows_wider_than_a_page_whole(tmp_path, in_memory):
    # 1,225 numbers (4.9 kB) a row, as the similar-clip search's descriptors: most rows
    # straddle two pages of the mapped file.
    x = clustered(n=200)
    rows = np.random.default_rng(7).normal(size=(200, 1225)).astype("<f4")
    (tmp_path / "payload").write_bytes(rows.tobytes())
    state = vector_index.build(tmp_path / "index", np.arange(200), x, n_lists=3,
                               payload=tmp_path / "payload", payload_width=1225)
    state.pop("lists")
    index = VectorIndex.open(tmp_path / "index", state, in_memory=in_memory)
    keys = [199, 0, 57, 57, 130, 1]
    found, got = index.payload(keys)
    assert found.all() and np.array_equal(got, rows[keys])
