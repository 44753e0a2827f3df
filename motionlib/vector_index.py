"""An inverted-file (IVF) index for nearest neighbours under the Euclidean distance.

The vectors are split into ``n_lists`` clusters by k-means; each cluster's vectors are
stored together, so a search compares the query with the cluster centres, then scans
only the nearest clusters until it has looked at ``probe_share`` of all vectors. Stored as
four ``.npy`` files in one folder (centres, list offsets, ids and float16 vectors, both
sorted by cluster); ``open(..., mmap=True)`` maps ids and vectors read-only, so every
process that opens the same folder shares one copy in the page cache.

Why not a graph index (HNSW): on the 2-core machines this project runs on, inserting a
million 105-dimensional vectors into an HNSW graph takes tens of minutes, while k-means
on a sample plus one assignment pass takes about a minute; the scan of 1 % of a million
float16 vectors costs a few milliseconds, well within a search's budget.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from motionlib.errors import InputError

FILES = ("centroids", "offsets", "ids", "vectors")
# Share of the vectors a search scans at least (nearest clusters first).
PROBE_SHARE = 0.01
# Lists a search scans at least.
MIN_LISTS = 8
# Vectors per cluster the index aims for (n_lists = n / LIST_SIZE, at least 1).
LIST_SIZE = 1024
TRAIN_SAMPLE = 65536
TRAIN_ITERATIONS = 10


def _sq_distances(x: np.ndarray, centres: np.ndarray, centre_norms: np.ndarray) -> np.ndarray:
    """(n, k) squared Euclidean distances, as |x|^2 - 2 x.c + |c|^2 (float32)."""
    x = np.asarray(x, dtype=np.float32)
    return (np.einsum("ij,ij->i", x, x)[:, None] - 2.0 * x @ centres.T) + centre_norms[None, :]


def train_centroids(vectors: np.ndarray, n_lists: int, *, seed: int = 0,
                    iterations: int = TRAIN_ITERATIONS, sample: int = TRAIN_SAMPLE) -> np.ndarray:
    """k-means (Lloyd) centres of a random sample of ``vectors``.

    Parameters
    ----------
    vectors : (n, d) float
    n_lists : number of centres, 1 <= n_lists <= n.

    Returns
    -------
    (n_lists, d) float32 centres. An emptied cluster is re-seeded with the sample point
    farthest from its centre, so every centre owns points.
    """
    n = len(vectors)
    if not 1 <= n_lists <= n:
        raise InputError(f"n_lists: must be between 1 and the {n} vectors, got {n_lists}")
    rng = np.random.default_rng(seed)
    pick = np.sort(rng.choice(n, size=min(n, max(sample, n_lists)), replace=False))
    x = np.asarray(vectors[pick], dtype=np.float32)
    centres = x[rng.choice(len(x), size=n_lists, replace=False)].copy()
    for _ in range(iterations):
        d = _sq_distances(x, centres, np.einsum("ij,ij->i", centres, centres))
        labels = d.argmin(axis=1)
        counts = np.bincount(labels, minlength=n_lists)
        sums = np.zeros_like(centres)
        np.add.at(sums, labels, x)
        filled = counts > 0
        centres[filled] = sums[filled] / counts[filled, None]
        empty = np.flatnonzero(~filled)
        if len(empty):
            far = np.argsort(d[np.arange(len(x)), labels])[::-1][:len(empty)]
            centres[empty[:len(far)]] = x[far]
    return centres


def assign(vectors: np.ndarray, centres: np.ndarray, chunk: int = 65536) -> np.ndarray:
    """(n,) index of the nearest centre of each vector."""
    norms = np.einsum("ij,ij->i", centres, centres)
    out = np.empty(len(vectors), dtype=np.int32)
    for first in range(0, len(vectors), chunk):
        part = np.asarray(vectors[first:first + chunk], dtype=np.float32)
        out[first:first + chunk] = _sq_distances(part, centres, norms).argmin(axis=1)
    return out


class IvfIndex:
    """Vectors grouped by nearest centre: list ``i`` is rows ``offsets[i]:offsets[i+1]``.

    Parameters
    ----------
    centroids : (n_lists, d) float32
    offsets : (n_lists + 1,) int64, increasing, from 0 to n.
    ids : (n,) int64 keys, sorted by list.
    vectors : (n, d) float16, in the order of ``ids``.
    """

    def __init__(self, centroids, offsets, ids, vectors):
        self.centroids = np.asarray(centroids, dtype=np.float32)
        self.offsets = np.asarray(offsets, dtype=np.int64)
        self.ids, self.vectors = ids, vectors
        self._norms = np.einsum("ij,ij->i", self.centroids, self.centroids)

    def __len__(self):
        return len(self.ids)

    @property
    def ndim(self):
        return self.centroids.shape[1]

    @classmethod
    def build(cls, ids: np.ndarray, vectors: np.ndarray, *, n_lists: int | None = None,
              seed: int = 0) -> IvfIndex:
        """Train centres on ``vectors`` (n, d) and group them; ``ids`` (n,) int keys."""
        ids = np.asarray(ids, dtype=np.int64)
        if vectors.ndim != 2 or len(vectors) != len(ids) or not len(ids):
            raise InputError(f"vectors: expected ({len(ids)}, d) with at least one row, got "
                             f"shape {vectors.shape}")
        n_lists = n_lists or max(1, len(ids) // LIST_SIZE)
        centres = train_centroids(vectors, n_lists, seed=seed)
        return cls._grouped(centres, ids, vectors, assign(vectors, centres))

    @classmethod
    def _grouped(cls, centres, ids, vectors, labels):
        order = np.argsort(labels, kind="stable")
        offsets = np.concatenate([[0], np.cumsum(np.bincount(labels, minlength=len(centres)))])
        return cls(centres, offsets, ids[order], np.asarray(vectors, dtype=np.float16)[order])

    def changed(self, remove: np.ndarray, add_ids: np.ndarray, add_vectors: np.ndarray) -> IvfIndex:
        """A new index without the ``remove`` keys and with the added vectors, grouped by
        the same centres (no retraining)."""
        keep = ~np.isin(self.ids, remove)
        lists = np.repeat(np.arange(len(self.centroids), dtype=np.int32), np.diff(self.offsets))
        ids = np.concatenate([np.asarray(self.ids)[keep], np.asarray(add_ids, dtype=np.int64)])
        vectors = np.concatenate([np.asarray(self.vectors)[keep],
                                  np.asarray(add_vectors, dtype=np.float16).reshape(-1, self.ndim)])
        labels = np.concatenate([lists[keep], assign(add_vectors, self.centroids)
                                 if len(add_ids) else np.zeros(0, dtype=np.int32)])
        return self._grouped(self.centroids, ids, vectors, labels)

    def search(self, query: np.ndarray, count: int, *, probe_share: float = PROBE_SHARE,
               min_lists: int = MIN_LISTS):
        """The ``count`` stored vectors nearest to ``query`` among the scanned lists.

        Lists are scanned nearest centre first until ``probe_share`` of all vectors (and
        at least ``count``) have been compared, and at least ``min_lists`` lists (a
        query near the border of its cluster has neighbours in the next ones).

        Returns
        -------
        ids : (<= count,) int64 keys, nearest first.
        distances : their squared Euclidean distances (from the float16 copies).
        """
        q = np.asarray(query, dtype=np.float32).reshape(1, -1)
        if q.shape[1] != self.ndim:
            raise InputError(f"query: expected {self.ndim} numbers, got {q.shape[1]}")
        sizes = np.diff(self.offsets)
        order = np.argsort(_sq_distances(q, self.centroids, self._norms)[0], kind="stable")
        need = max(count, int(np.ceil(probe_share * len(self))))
        scanned = np.cumsum(sizes[order])
        lists = order[:max(int(np.searchsorted(scanned, need)) + 1, min_lists)]
        spans = [(self.offsets[i], self.offsets[i + 1]) for i in np.sort(lists) if sizes[i]]
        if not spans:
            return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.float32)
        rows = np.concatenate([np.arange(a, b) for a, b in _merged(spans)])
        block = np.concatenate([self.vectors[a:b] for a, b in _merged(spans)]).astype(np.float32)
        diff = block - q
        d = np.einsum("ij,ij->i", diff, diff)
        top = np.argpartition(d, count - 1)[:count] if len(d) > count else np.arange(len(d))
        top = top[np.argsort(d[top], kind="stable")]
        return np.asarray(self.ids[rows[top]], dtype=np.int64), d[top]

    def save(self, folder: Path) -> dict:
        """Write the four arrays into ``folder``; returns {file name: bytes}."""
        folder.mkdir(parents=True, exist_ok=True)
        sizes = {}
        for name in FILES:
            path = folder / f"{name}.npy"
            np.save(path, np.asarray(getattr(self, name)))
            sizes[path.name] = path.stat().st_size
        (folder / "sizes.json").write_text(json.dumps(sizes))
        return sizes

    @classmethod
    def open(cls, folder: Path, *, mmap: bool = True) -> IvfIndex:
        """Read an index written by ``save``; ids and vectors memory-mapped when ``mmap``.

        ValueError names the file that is missing, truncated or inconsistent."""
        arrays = {}
        for name in FILES:
            path = folder / f"{name}.npy"
            try:
                arrays[name] = np.load(path, mmap_mode="r" if mmap and name in ("ids", "vectors")
                                       else None)
            except (OSError, ValueError, EOFError) as exc:
                raise InputError(f"{path}: cannot be read ({exc})") from exc
        centroids, offsets = arrays["centroids"], arrays["offsets"]
        if (offsets.shape != (len(centroids) + 1,) or offsets[-1] != len(arrays["ids"])
                or arrays["vectors"].shape != (len(arrays["ids"]), centroids.shape[1])):
            raise InputError(f"{folder}: its arrays disagree (centroids {centroids.shape}, "
                             f"offsets {offsets.shape}, ids {arrays['ids'].shape}, vectors "
                             f"{arrays['vectors'].shape})")
        return cls(**arrays)


def _merged(spans):
    """Adjacent (start, stop) row ranges joined, so neighbouring lists read as one."""
    out = [list(spans[0])]
    for a, b in spans[1:]:
        if a == out[-1][1]:
            out[-1][1] = b
        else:
            out.append([a, b])
    return out
