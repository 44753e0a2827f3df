"""A nearest-neighbour index under the Euclidean distance that grows by appending.

One index is a folder holding:

- ``base.faiss``: a faiss inverted-file index (``IndexIVFFlat``: k-means centres, float32
  vectors grouped by nearest centre, with their int64 keys), and ``base_ids.npy``, the same
  keys in one array. Written once, when the folder is made.
- ``delta_ids.i64`` / ``delta_vectors.f32``: keys and vectors added since, appended as raw
  records.
- ``removed.i64``: keys removed since, appended.
- ``payload.f32`` / ``delta_payload.f32`` (optional): a fixed-width float32 row per base
  key (in ``base_ids`` order, which is ascending) and per added key, for what a caller
  needs of a result besides its key (the similar-clip search keeps the full motion
  descriptors there, so ranking reads no database row).

How many records of each file count is the caller's *state* (``{"ndim", "base", "delta",
"removed", "payload"}``, the last the payload's width), kept in a manifest that the caller replaces atomically after an append. A
reader opens a folder at a state and sees exactly those records: bytes appended later, or
left by a writer that crashed, lie past its counts, and the next append overwrites them.
So an update writes only what changed, and every process sees a consistent index.

``open`` reads ``base.faiss`` memory-mapped (``IO_FLAG_MMAP | IO_FLAG_READ_ONLY``), so the
processes of a machine share one copy in the page cache, or with ``in_memory`` into the
process's own memory, where a search scans its lists in under half the time (the mapped
file's small pages cost that much); it maps the delta and payload files. A search
asks the base's ``nprobe`` nearest lists and compares the query with every delta vector
(the caller rebuilds the folder, retraining the centres, before the delta grows large).
"""

from __future__ import annotations

import mmap
import os
from pathlib import Path

import faiss
import numpy as np

from motionlib.errors import InputError

BASE, BASE_IDS = "base.faiss", "base_ids.npy"
DELTA_IDS, DELTA_VECTORS, REMOVED = "delta_ids.i64", "delta_vectors.f32", "removed.i64"
PAYLOAD, DELTA_PAYLOAD = "payload.f32", "delta_payload.f32"
# Vectors per list the index aims for (n_lists = n / LIST_SIZE, at least 1).
LIST_SIZE = 1024
# Lists a search scans: the nearest centres first.
NPROBE = 16
TRAIN_PER_LIST = 64
TRAIN_ITERATIONS = 10
# Searches run on the calling thread: a web process answers one request per thread, and
# OpenMP's team would fight the other processes of a small machine for its cores.
faiss.omp_set_num_threads(1)


def empty_state(ndim: int, base: int, payload: int = 0) -> dict:
    return {"ndim": int(ndim), "base": int(base), "delta": 0, "removed": 0,
            "payload": int(payload)}


def build(folder: Path, ids: np.ndarray, vectors: np.ndarray, *, n_lists: int | None = None,
          seed: int = 0, threads: int | None = None, payload: Path | None = None,
          payload_width: int = 0) -> dict:
    """Train centres on ``vectors`` (n, d), write the index of ``ids`` (n,, ascending) into
    the new ``folder`` (fsynced) and return its state.

    ``payload``: a file of ``payload_width`` float32 per key, in ``ids`` order, moved into
    the folder. ``threads``: cores for training and grouping (default: all; searches use
    one)."""
    ids = np.ascontiguousarray(ids, dtype=np.int64)
    if len(ids) > 1 and not np.all(np.diff(ids) > 0):
        raise InputError("ids: must be ascending and unique")
    if payload is not None and payload.stat().st_size != len(ids) * payload_width * 4:
        raise InputError(f"{payload}: {payload.stat().st_size} bytes, expected {len(ids)} rows "
                         f"of {payload_width} float32")
    vectors = np.ascontiguousarray(vectors, dtype=np.float32)
    if vectors.ndim != 2 or len(vectors) != len(ids) or not len(ids):
        raise InputError(f"vectors: expected ({len(ids)}, d) with at least one row, got "
                         f"shape {vectors.shape}")
    n, d = vectors.shape
    n_lists = n_lists or max(1, n // LIST_SIZE)
    if not 1 <= n_lists <= n:
        raise InputError(f"n_lists: must be between 1 and the {n} vectors, got {n_lists}")
    index = _trained(vectors, n_lists, seed, threads)
    _add_keyed(index, ids, vectors, threads)
    folder.mkdir(parents=True)
    faiss.write_index(index, str(folder / BASE))
    np.save(folder / BASE_IDS, ids)
    if payload is not None:
        os.replace(payload, folder / PAYLOAD)
    for name in (DELTA_IDS, DELTA_VECTORS, REMOVED, DELTA_PAYLOAD) + (() if payload else (PAYLOAD,)):
        (folder / name).touch()
    for path in folder.iterdir():
        fsync(path)
    fsync(folder)
    return empty_state(d, n, payload_width if payload is not None else 0) | {"lists": n_lists}


def _trained(vectors, n_lists, seed, threads):
    """An IndexIVFFlat of ``vectors`` keyed by row (keys are added by the caller)."""
    previous = faiss.omp_get_max_threads()
    faiss.omp_set_num_threads(threads or os.cpu_count() or 1)
    try:
        d = vectors.shape[1]
        index = faiss.IndexIVFFlat(faiss.IndexFlatL2(d), d, n_lists)
        index.cp.seed = seed
        # k-means on a sample of TRAIN_PER_LIST points per list, TRAIN_ITERATIONS rounds:
        # faiss's defaults (256 per list, 25 rounds) cost ten times as much for centres
        # that only decide which lists a search scans.
        index.cp.niter = TRAIN_ITERATIONS
        index.cp.max_points_per_centroid = TRAIN_PER_LIST
        # faiss warns below 39 training points per list; small libraries have fewer.
        index.cp.min_points_per_centroid = 1
        index.verbose = False
        index.train(vectors)
        return index
    finally:
        faiss.omp_set_num_threads(previous)


def _add_keyed(index, ids, vectors, threads):
    previous = faiss.omp_get_max_threads()
    faiss.omp_set_num_threads(threads or os.cpu_count() or 1)
    try:
        index.add_with_ids(vectors, ids)
    finally:
        faiss.omp_set_num_threads(previous)


def append(folder: Path, state: dict, add_ids=(), add_vectors=None, remove_ids=(),
           add_payload=None) -> dict:
    """Append added keys, vectors and payload rows, and removed keys, after ``state``'s
    records (bytes past them are overwritten); fsync and return the new state. The caller
    serialises writers and publishes the state."""
    d, w = state["ndim"], state.get("payload", 0)
    add_ids = np.ascontiguousarray(add_ids, dtype="<i8")
    add_vectors = np.ascontiguousarray(
        np.zeros((0, d)) if add_vectors is None else add_vectors, dtype="<f4").reshape(-1, d)
    remove_ids = np.ascontiguousarray(remove_ids, dtype="<i8")
    add_payload = (np.ascontiguousarray(add_payload, dtype="<f4").reshape(-1, w)
                   if w and add_payload is not None else np.zeros((0, w), dtype="<f4"))
    if len(add_vectors) != len(add_ids) or (w and len(add_payload) != len(add_ids)):
        raise InputError(f"add_vectors, add_payload: expected ({len(add_ids)}, {d}) and "
                         f"({len(add_ids)}, {w}), got {add_vectors.shape}, {add_payload.shape}")
    for name, at, data in ((DELTA_IDS, state["delta"] * 8, add_ids),
                           (DELTA_VECTORS, state["delta"] * 4 * d, add_vectors),
                           (DELTA_PAYLOAD, state["delta"] * 4 * w, add_payload),
                           (REMOVED, state["removed"] * 8, remove_ids)):
        with open(folder / name, "r+b") as fh:
            fh.truncate(at)
            fh.seek(at)
            fh.write(data.tobytes())
            fh.flush()
            os.fsync(fh.fileno())
    return {**state, "delta": state["delta"] + len(add_ids),
            "removed": state["removed"] + len(remove_ids)}


def check(folder: Path, state: dict) -> None:
    """InputError naming a file of ``folder`` that is missing or shorter than ``state``."""
    d, w = state["ndim"], state.get("payload", 0)
    need = {BASE: 1, BASE_IDS: 1, DELTA_IDS: state["delta"] * 8,
            DELTA_VECTORS: state["delta"] * 4 * d, REMOVED: state["removed"] * 8,
            PAYLOAD: state["base"] * 4 * w, DELTA_PAYLOAD: state["delta"] * 4 * w}
    for name, size in need.items():
        try:
            found = (folder / name).stat().st_size
        except OSError as exc:
            raise InputError(f"{folder / name}: cannot be read ({exc.strerror})") from exc
        if found < size:
            raise InputError(f"{folder / name}: {found} bytes, its state needs {size}")


class VectorIndex:
    """A folder opened at a state. ``search`` finds the nearest live keys; ``keys`` lists
    them."""

    def __init__(self, folder: Path, state: dict, base=None, base_ids=None, in_memory=False):
        check(folder, state)
        self.folder, self.state = folder, dict(state)
        d = state["ndim"]
        if base is None:
            flags = 0 if in_memory else faiss.IO_FLAG_MMAP | faiss.IO_FLAG_READ_ONLY
            try:
                base = faiss.read_index(str(folder / BASE), flags)
                base_ids = np.load(folder / BASE_IDS, mmap_mode=None if in_memory else "r")
            except (RuntimeError, OSError, ValueError) as exc:
                raise InputError(f"{folder}: its base index cannot be read ({exc})") from exc
            if base.ntotal != state["base"] or base.d != d or len(base_ids) != base.ntotal:
                raise InputError(f"{folder}: holds {base.ntotal} vectors of {base.d} numbers "
                                 f"and {len(base_ids)} keys, its state says {state['base']} of {d}")
        self.base, self.base_ids = base, base_ids
        self.delta_ids = _mapped(folder / DELTA_IDS, "<i8", (state["delta"],))
        self.delta_vectors = _mapped(folder / DELTA_VECTORS, "<f4", (state["delta"], d))
        self._delta_norms = np.einsum("ij,ij->i", self.delta_vectors, self.delta_vectors)
        self.removed = np.unique(_mapped(folder / REMOVED, "<i8", (state["removed"],)))
        w = state.get("payload", 0)
        self._payload = _Rows(folder / PAYLOAD, (state["base"] if w else 0, w))
        self._delta_payload = _Rows(folder / DELTA_PAYLOAD, (state["delta"] if w else 0, w))
        self._delta_rows = None

    @classmethod
    def open(cls, folder: Path, state: dict, in_memory: bool = False) -> VectorIndex:
        """``in_memory``: the base read into this process's memory rather than mapped."""
        return cls(folder, state, in_memory=in_memory)

    def at(self, state: dict) -> VectorIndex:
        """The same folder at a later state: the mapped base is kept, the delta re-read."""
        return VectorIndex(self.folder, state, self.base, self.base_ids)

    @property
    def ndim(self):
        return self.state["ndim"]

    @property
    def n_lists(self):
        return self.base.nlist

    def payload(self, keys) -> tuple[np.ndarray, np.ndarray]:
        """(found, rows): which of ``keys`` the index holds (base or added, removed or
        not), and their payload rows (len(keys), width) float32, zeros where not found."""
        keys = np.asarray(keys, dtype=np.int64)
        w = self.state.get("payload", 0)
        rows = np.zeros((len(keys), w), dtype=np.float32)
        found = np.zeros(len(keys), dtype=bool)
        if not w or not len(keys):
            return found, rows
        at = np.searchsorted(self.base_ids, keys)
        inside = at < len(self.base_ids)
        hit = inside.copy()
        hit[inside] = np.asarray(self.base_ids[at[inside]]) == keys[inside]
        if hit.any():
            rows[hit] = self._payload.take(at[hit])
        if len(self.delta_ids):
            if self._delta_rows is None:
                self._delta_rows = {int(k): r for r, k in enumerate(self.delta_ids)}
            for i in np.flatnonzero(~hit):
                r = self._delta_rows.get(int(keys[i]))
                if r is not None:
                    rows[i], hit[i] = self._delta_payload.take([r])[0], True
        found[:] = hit
        return found, rows

    def keys(self) -> np.ndarray:
        """The live keys (base and added, less removed), sorted."""
        keys = np.union1d(np.asarray(self.base_ids), np.asarray(self.delta_ids))
        return np.setdiff1d(keys, self.removed, assume_unique=True)

    def __len__(self):
        return len(self.keys())

    def search(self, query: np.ndarray, count: int, *, nprobe: int | None = None,
               vectors: bool = False):
        """The ``count`` live keys nearest to ``query`` among the ``nprobe`` (default
        ``NPROBE``) nearest lists and the added vectors.

        Returns
        -------
        keys : (<= count,) int64, nearest first.
        distances : their squared Euclidean distances (float32).
        vectors : with ``vectors=True``, their vectors (<= count, ndim) float32, as stored:
            read from the lists the search scanned, so a caller that measures the
            candidates again touches no other file.
        """
        q = np.ascontiguousarray(query, dtype=np.float32).reshape(1, -1)
        if q.shape[1] != self.ndim:
            raise InputError(f"query: expected {self.ndim} numbers, got {q.shape[1]}")
        # Removed keys still sit in the files: ask for more, to drop them (a caller that
        # finds too few asks again for more).
        want = count + min(len(self.removed), count)
        params = faiss.SearchParametersIVF(nprobe=min(nprobe or NPROBE, self.base.nlist))
        k = min(want, self.base.ntotal)
        if vectors:
            dist, keys, rows = self.base.search_and_reconstruct(q, k, params=params)
            rows = rows[0]
        else:
            dist, keys = self.base.search(q, k, params=params)
            rows = np.zeros((len(keys[0]), 0), dtype=np.float32)
        keys, dist = keys[0], dist[0]
        found = keys >= 0
        keys, dist, rows = keys[found], dist[found], rows[found]
        if len(self.delta_ids):
            dd = self._delta_norms - 2.0 * (self.delta_vectors @ q[0]) + float(q[0] @ q[0])
            near = np.argsort(dd, kind="stable")[:want] if len(dd) <= want else \
                np.argpartition(dd, want - 1)[:want]
            keys = np.concatenate([keys, np.asarray(self.delta_ids[near], dtype=np.int64)])
            dist = np.concatenate([dist, np.maximum(dd[near], 0).astype(np.float32)])
            rows = np.concatenate([rows, self.delta_vectors[near] if vectors else
                                   np.zeros((len(near), 0), dtype=np.float32)])
        if len(self.removed):
            live = ~np.isin(keys, self.removed)
            keys, dist, rows = keys[live], dist[live], rows[live]
        order = np.argsort(dist, kind="stable")[:count]
        if vectors:
            return keys[order].astype(np.int64), dist[order], np.asarray(rows[order])
        return keys[order].astype(np.int64), dist[order]


class _Rows:
    """A file of fixed-width float32 rows, mapped for reads of a few rows anywhere in it.

    The mapping is advised random: a page fault reads that page, not the device's
    read-ahead window around it (megabytes on some machines, for a row of 4.9 kB). A
    gather first asks the kernel for all its rows at once, so their reads from disk, when
    the page cache lost them, overlap instead of following one another."""

    def __init__(self, path, shape):
        self.shape, self._map = shape, None
        if not shape[0] or not shape[1]:
            self.rows = np.zeros(shape, dtype="<f4")
            return
        with open(path, "rb") as fh:
            self._map = mmap.mmap(fh.fileno(), shape[0] * shape[1] * 4, access=mmap.ACCESS_READ)
        self._map.madvise(mmap.MADV_RANDOM)
        self.rows = np.frombuffer(self._map, dtype="<f4").reshape(shape)

    def take(self, at) -> np.ndarray:
        """Rows ``at`` (indices), (len(at), width) float32."""
        at = np.asarray(at, dtype=np.int64)
        if self._map is not None and len(at) > 1:
            width = self.shape[1] * 4
            for row in np.unique(at).tolist():
                start = row * width // mmap.PAGESIZE * mmap.PAGESIZE
                self._map.madvise(mmap.MADV_WILLNEED, start, row * width + width - start)
        return self.rows[at]


def _mapped(path, dtype, shape):
    if not shape[0]:
        return np.zeros(shape, dtype=dtype)
    return np.memmap(path, dtype=dtype, mode="r", shape=shape)


def fsync(path):
    """Flush a file or a folder (its entries) to disk."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)
