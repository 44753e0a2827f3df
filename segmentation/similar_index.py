"""The approximate nearest-neighbour index behind "find similar": one file per project.

What it indexes: each described library segment's *profile* (the first
``similarity.PROFILE_ROWS`` rows of its descriptor, flattened: 3 x 35 = 105 numbers),
under the squared Euclidean distance, which is the first stage of the exact search
(``similarity.shortlist_by_profile``). The index only proposes candidates; their exact
profile distances and the DTW re-ranking are computed from the database rows, so an
index can make a search slower or (rarely) miss a neighbour, never return a segment the
database no longer has or one the caller may not see.

Files, in ``settings.SIMILAR_INDEX_DIR`` (``$CUTROOM_SIMILAR_INDEX_DIR``, default
``var/similar``):

- ``project_<id>.g<generation>/``: an inverted-file index (``motionlib.vector_index``:
  k-means centres, and the float16 vectors with their segment ids grouped by centre).
  Web processes map ids and vectors read-only, so all of them on a machine share one
  copy in the page cache (a million segments: about 220 MB).
- ``project_<id>.json``: the manifest, replaced atomically last: format version, vector
  width, the index file's name and size, how many vectors it holds and the highest
  segment id it has seen. A crash while writing leaves the previous manifest and file in
  force (a new generation is written beside the old one and only then named; the old
  one is deleted after, and processes that still map it keep reading it until they see
  the new manifest).

Staying in step with the database (which is the truth):

- Segments newer than the manifest's ``max_id`` (the *delta*) are read with each
  search's candidates, in the same query, and measured exactly, so a search never waits
  for the index.
- Deleted segments left in the file are dropped when candidates are read back.
- ``update`` (a Celery task queued when library rows change, and run by
  ``manage.py similar_index``) compares the index's keys with the database's ids, removes
  and adds the difference (added vectors join their nearest existing centre) and writes a
  new generation; ``build`` trains new centres and writes one from scratch, which
  ``update`` does itself when much was removed or the library has doubled.
- ``open_index`` checks a manifest the first time a process sees it: a missing or
  unreadable file, another format or width, or a vector count that disagrees with the
  database all mean "not usable": the search falls back to the exact scan and a rebuild
  is queued.
"""

import fcntl
import json
import logging
import os
import shutil
import threading
import time
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from django.conf import settings
from django.db import connections, transaction

from motionlib import similarity
from motionlib.vector_index import IvfIndex
from segmentation import workers
from segmentation.models import LibrarySegment

log = logging.getLogger(__name__)

FORMAT = 1
# A search scans at least this share of the index (nearest clusters first): chosen on the
# million-segment benchmark for recall@10 >= 0.95 against the exact scan.
PROBE_SHARE = 0.005
# An update that would remove more than this share of the vectors, or grow the index past
# GROWTH times the size its centres were trained on, retrains instead (clusters drift).
REBUILD_SHARE = 0.25
GROWTH = 2.0
# When the delta (segments newer than the file) grows past this, an update is queued.
DELTA_LIMIT = 5000
READ_CHUNK = 20000


class IndexUnusable(Exception):
    """The index of a project cannot be used; the message says why."""


def index_dir() -> Path:
    return Path(settings.SIMILAR_INDEX_DIR)


def manifest_path(project_id) -> Path:
    return index_dir() / f"project_{project_id}.json"


def described(project_id):
    return LibrarySegment.objects.filter(project_id=project_id, profile__isnull=False)


def as_vectors(blobs, n_features=None):
    """(n, PROFILE_ROWS * n_features) float32 profiles from the stored bytes."""
    vectors = np.stack([np.frombuffer(bytes(b), dtype="<f4") for b in blobs]) if blobs else (
        np.zeros((0, similarity.PROFILE_ROWS * (n_features or 0)), dtype=np.float32))
    return vectors


@contextmanager
def _locked(project_id):
    """One writer per project and machine (an update and a rebuild never interleave)."""
    index_dir().mkdir(parents=True, exist_ok=True)
    with open(index_dir() / f"project_{project_id}.lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(fh, fcntl.LOCK_UN)


def read_manifest(project_id):
    """The manifest dict, or IndexUnusable naming what is wrong with it."""
    path = manifest_path(project_id)
    try:
        manifest = json.loads(path.read_text())
    except FileNotFoundError as exc:
        raise IndexUnusable(f"{path}: no index yet") from exc
    except (OSError, ValueError) as exc:
        raise IndexUnusable(f"{path}: unreadable ({exc})") from exc
    if not isinstance(manifest, dict) or manifest.get("format") != FORMAT:
        raise IndexUnusable(f"{path}: format {manifest.get('format') if isinstance(manifest, dict) else '?'}"
                            f", this version reads format {FORMAT}")
    folder = index_dir() / str(manifest.get("file"))
    try:
        sizes = {p.name: p.stat().st_size for p in folder.glob("*.npy")}
    except OSError as exc:
        raise IndexUnusable(f"{folder}: unreadable ({exc.strerror})") from exc
    if sizes != manifest.get("bytes_per_file"):
        raise IndexUnusable(f"{folder}: files {sizes or 'missing'}, the manifest says "
                            f"{manifest.get('bytes_per_file')}")
    return manifest


def _fingerprint(project_id):
    """[count, max id, sum of ids] of the described segments: cheap to compare, and
    changed by any insert or delete."""
    from django.db.models import Count, Max, Sum

    found = described(project_id).aggregate(n=Count("id"), top=Max("id"), total=Sum("id"))
    return [found["n"], found["top"] or 0, int(found["total"] or 0)]


def _write_generation(project_id, index, max_id, fingerprint, trained_on):
    """Save ``index`` as a new generation and name it in the manifest (atomically).

    ``fingerprint`` is the database's, read before the index was."""
    generation = time.time_ns()
    name = f"project_{project_id}.g{generation}"
    folder = index_dir() / name
    sizes = index.save(folder)
    for path in folder.iterdir():
        _fsync(path)
    _fsync(folder)
    manifest = {"format": FORMAT, "ndim": index.ndim, "file": name, "bytes": sum(sizes.values()),
                "bytes_per_file": sizes, "count": len(index), "lists": len(index.centroids),
                "trained_on": trained_on, "max_id": int(max_id), "generation": generation,
                "fingerprint": fingerprint,
                "built_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    tmp = manifest_path(project_id).with_suffix(".json.tmp")
    tmp.write_text(json.dumps(manifest, indent=1))
    _fsync(tmp)
    os.replace(tmp, manifest_path(project_id))
    _fsync(index_dir())
    for old in index_dir().glob(f"project_{project_id}.g*"):
        if old.name != name:
            # Processes that map the old files keep them (unlinked inodes live on).
            shutil.rmtree(old, ignore_errors=True)
    return manifest


def _fsync(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


def _chunks(queryset):
    """(ids, vectors) of a queryset of described segments, READ_CHUNK rows at a time."""
    last = 0
    while True:
        rows = list(queryset.filter(id__gt=last).order_by("id")
                    .values_list("id", "profile")[:READ_CHUNK])
        if not rows:
            return
        last = rows[-1][0]
        yield np.array([r[0] for r in rows], dtype=np.int64), as_vectors([r[1] for r in rows])


def build(project_id):
    """Write a project's index from scratch; returns the manifest (None: nothing to index)."""
    with _locked(project_id):
        return _build(project_id)


def _build(project_id):
    fingerprint = _fingerprint(project_id)
    parts = list(_chunks(described(project_id)))
    if not parts:
        manifest_path(project_id).unlink(missing_ok=True)
        return None
    widths = {v.shape[1] for _, v in parts}
    if len(widths) > 1:
        raise IndexUnusable(f"project {project_id}: segment profiles have {sorted(widths)} "
                            "numbers; rebuild the library's descriptors")
    ids = np.concatenate([k for k, _ in parts])
    vectors = np.concatenate([v for _, v in parts])
    del parts
    index = IvfIndex.build(ids, vectors, seed=project_id)
    manifest = _write_generation(project_id, index, int(ids[-1]), fingerprint, len(ids))
    log.info("similar index of project %s built: %s vectors", project_id, manifest["count"])
    return manifest


def update(project_id):
    """Bring a project's index in step with the database: remove the vectors of deleted
    segments, add the missing ones, write a new generation. Builds when there is no usable
    index, too much would be removed, or the library outgrew the index's centres.
    Returns the manifest (unchanged when in step)."""
    with _locked(project_id):
        try:
            manifest = read_manifest(project_id)
            index = IvfIndex.open(index_dir() / manifest["file"], mmap=False)
        except (IndexUnusable, ValueError) as exc:
            log.info("similar index of project %s rebuilt: %s", project_id, exc)
            return _build(project_id)
        fingerprint = _fingerprint(project_id)
        if fingerprint == manifest.get("fingerprint"):
            return manifest
        keys = np.asarray(index.ids, dtype=np.int64)
        ids = np.fromiter(described(project_id).values_list("id", flat=True).iterator(chunk_size=20000),
                          dtype=np.int64)
        removed = np.setdiff1d(keys, ids, assume_unique=True)
        added = np.setdiff1d(ids, keys, assume_unique=True)
        if (len(removed) > REBUILD_SHARE * max(len(keys), 1)
                or len(ids) > GROWTH * manifest.get("trained_on", len(keys))):
            return _build(project_id)
        add_ids, add_vectors = [], []
        for first in range(0, len(added), READ_CHUNK):
            part = [int(i) for i in added[first:first + READ_CHUNK]]
            rows = dict(LibrarySegment.objects.filter(pk__in=part).values_list("id", "profile"))
            part = [pk for pk in part if pk in rows]  # deleted meanwhile
            add_ids += part
            add_vectors += [rows[pk] for pk in part]
        vectors = as_vectors(add_vectors, index.ndim // similarity.PROFILE_ROWS)
        if len(vectors) and vectors.shape[1] != index.ndim:
            return _build(project_id)
        index = index.changed(removed, np.array(add_ids, dtype=np.int64), vectors)
        max_id = max(int(ids.max()) if len(ids) else 0, manifest["max_id"])
        return _write_generation(project_id, index, max_id, fingerprint,
                                 manifest.get("trained_on", len(keys)))


def schedule_update(project_id):
    """Queue ``update`` for when the current transaction commits (a worker must see the
    rows). A broker that cannot be reached costs freshness of the file only: searches
    read newer segments from the database."""
    transaction.on_commit(lambda: workers.send(
        "update_similar_index", project_id, then="searches read the newer segments from the database"))


def _candidates_or_newer(pool, ids, project_id, after):
    """``pool``'s rows that are among ``ids`` or newer than the index file (the delta), in
    one query: [(id, capture, start, stop, profile)].

    The delta is found by row comparisons on (project, id), so that the database walks
    the ``libseg_described`` index from ``(project, after)`` to the project's end: with a
    plain ``project_id = p AND id > after`` PostgreSQL estimates the project's share of
    all newer rows and often prefers the primary key, then filters every newer row of
    every project. On PostgreSQL the delta's ids are an InitPlan joined to the candidates'
    as one array, so the rows themselves are one scan of the primary key (an OR of the two
    lets the planner pick a library-list index and scan the project: ~0.5 s at a million).
    """
    table = LibrarySegment._meta.db_table
    newer = (f'SELECT u.id FROM "{table}" u WHERE u.profile IS NOT NULL AND '
             '(u.project_id, u.id) > (%s, %s) AND (u.project_id, u.id) < (%s, 0)')
    marks = ", ".join(["%s"] * len(ids))
    if connections[pool.db].vendor == "postgresql":
        where = f'"{table}"."id" = ANY(ARRAY[{marks}]::bigint[] || ARRAY({newer}))'
    else:
        where = f'("{table}"."id" IN ({marks or "NULL"}) OR "{table}"."id" IN ({newer}))'
    return list(pool.extra(where=[where], params=[*ids, project_id, after, project_id + 1])
                .values_list("id", "capture_id", "start", "stop", "profile"))


@dataclass
class OpenIndex:
    """A project's index as this process sees it: its manifest and the mapped file.

    Segments newer than the file (the *delta*) are not cached here: every search reads
    them from the database in the same query as its candidates (``shortlist``), filtered
    by what the caller may see, so a search costs no query of its own for freshness."""

    project_id: int
    manifest: dict
    index: object
    update_queued: bool = False

    def nearest(self, vector, count):
        """Up to ``count`` segment ids of the file nearest to a profile vector, nearest
        first. Ids may include deleted segments."""
        return self.index.search(vector, count, probe_share=PROBE_SHARE)[0]

    def note_delta(self, newer):
        """Queue an update (once per generation) when ``newer`` segments outnumber
        ``DELTA_LIMIT``: every search reads them."""
        if newer > DELTA_LIMIT and not self.update_queued:
            self.update_queued = True
            schedule_update(self.project_id)

    @property
    def size(self):
        return len(self.index)


_open = {}
_open_lock = threading.Lock()


def open_index(project_id):
    """The project's usable index for this process, or None (the caller scans exactly).

    The manifest is re-read when its file changes, so a new generation is picked up at
    the next search. The first time a process sees a generation it checks it against the
    database; an index that cannot be used queues a rebuild.
    """
    try:
        stamp = manifest_path(project_id).stat().st_mtime_ns
    except OSError:
        stamp = None
    with _open_lock:
        current = _open.get(project_id)
        if current is not None and current[0] == stamp:
            opened = current[1]
        else:
            opened = _open_checked(project_id)
            _open[project_id] = (stamp, opened)
    return opened


def _open_checked(project_id):
    try:
        manifest = read_manifest(project_id)
        index = IvfIndex.open(index_dir() / manifest["file"])
        if len(index) != manifest["count"]:
            raise IndexUnusable(f"{manifest['file']}: holds {len(index)} vectors, the "
                                f"manifest says {manifest['count']}")
        in_db = described(project_id).filter(id__lte=manifest["max_id"]).count()
        if in_db != manifest["count"]:
            # Rows changed since the file was written (a crash before the update, or
            # transactions that committed out of id order): usable, but queue an update.
            log.info("similar index of project %s: %s vectors, %s segments in the database; "
                     "updating", project_id, manifest["count"], in_db)
            schedule_update(project_id)
    except (IndexUnusable, ValueError) as exc:
        if described(project_id).exists():
            log.warning("similar index of project %s not used: %s; rebuilding", project_id, exc)
            schedule_update(project_id)
        return None
    return OpenIndex(project_id, manifest, index)


# The first look at the index asks for this many candidates per shortlisted segment; a
# look that finds too few visible ones asks for four times as many, up to MAX_CANDIDATES.
OVERSAMPLE = 4
MAX_CANDIDATES = 4096


def shortlist(index, query, pool, n):
    """Ids of the ``n`` segments of ``pool`` whose profiles are nearest to ``query``'s,
    nearest first, as the exact scan orders them (ties: newest first; one span once).

    ``pool`` is the caller's visible, filtered queryset; the index proposes candidates
    and ``pool`` decides which exist and may be shown. Returns None when even
    ``MAX_CANDIDATES`` candidates leave fewer than ``n`` (a very selective filter): the
    caller then scans exactly.
    """
    vector = np.asarray(query[:similarity.PROFILE_ROWS], dtype=np.float32).ravel()
    count = max(OVERSAMPLE * n, 64)
    after = index.manifest["max_id"]
    while True:
        candidates = index.nearest(vector, count)
        rows = _candidates_or_newer(pool, [int(c) for c in candidates], index.project_id, after)
        index.note_delta(sum(r[0] > after for r in rows))
        found = _nearest_unique(rows, query, n)
        exhausted = len(candidates) < count
        if len(found) >= n or exhausted:
            return found
        if count >= MAX_CANDIDATES:
            return None
        count *= OVERSAMPLE


def _nearest_unique(rows, query, n):
    """The exact scan's order over ``rows`` (id, capture, start, stop, profile)."""
    if not rows:
        return []
    rows.sort(key=lambda r: -r[0])
    seen, unique = set(), []
    for pk, capture_id, start, stop, blob in rows:
        if (capture_id, start, stop) not in seen:
            seen.add((capture_id, start, stop))
            unique.append((pk, blob))
    profiles = as_vectors([b for _, b in unique]).reshape(len(unique), similarity.PROFILE_ROWS, -1)
    order = similarity.shortlist_by_profile(query, profiles, n)
    return [unique[i][0] for i in order]


def forget():
    """Drop this process's open indexes (tests; after a rebuild in the same process)."""
    with _open_lock:
        _open.clear()
