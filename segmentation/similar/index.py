"""The approximate nearest-neighbour index behind "find similar": one folder per project.

What it indexes: each described library segment's *profile* (the first
``similarity.PROFILE_ROWS`` rows of its descriptor, flattened: 3 x 35 = 105 numbers),
under the squared Euclidean distance, which is the first stage of the exact search
(``similarity.shortlist_by_profile``). The index only proposes candidates; the database
says which of them exist and the caller may see, so an index can make a search slower or
(rarely) miss a neighbour, never return a segment the database no longer has or one the
caller may not see.

Files, in ``settings.SIMILAR_INDEX_DIR`` (``$CUTROOM_SIMILAR_INDEX_DIR``, default
``var/similar``):

- ``project_<id>.g<generation>/``: a ``motionlib.vector_index`` folder: a faiss
  inverted-file index written when the generation was built, and the keys and vectors
  added and the keys removed since, appended. Web processes map it read-only, so all of
  them on a machine share one copy in the page cache, except the base's profiles, which
  each reads into its own memory (``settings.SIMILAR_INDEX_IN_MEMORY``).
- ``project_<id>.json``: the manifest, replaced atomically after every write: format
  version, the generation's folder, how many base, added and removed records count (the
  folder's *state*), how many vectors it holds and the highest segment id it has seen. A
  reader sees exactly the records its manifest counts, so a crash while appending leaves
  the previous state in force, and an update is visible to every process at once.

Staying in step with the database (which is the truth):

- Segments newer than the manifest's ``max_id`` (the *delta*) are read by each process
  once, after a search's candidates query has reported them, and measured exactly with
  every search (``OpenIndex``), so a search never waits for the index.
- ``update`` (a Celery task queued when library rows change, and run by
  ``manage.py similar_index``) compares the index's keys with the database's ids and
  appends the difference: it writes the added vectors and removed keys, not the index.
  When the appended records outgrow ``COMPACT_SHARE`` of the base, or there is no usable
  index, it *compacts*: ``build`` trains new centres over the whole library and writes a
  new generation beside the old one before naming it (processes that still map the old
  one keep reading it until they see the new manifest).
- ``open_index`` checks a manifest the first time a process sees a generation: a missing
  or short file, another format or width, or a vector count that disagrees with the
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
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from django.conf import settings
from django.db import connections, transaction
from django.db.models import BigIntegerField, BinaryField, Case, F, When
from django.db.models.expressions import RawSQL

from motionlib import similarity, vector_index
from motionlib.errors import InputError
from segmentation import workers
from segmentation.db import statements
from segmentation.errors import Invalid
from segmentation.models import LibrarySegment
from segmentation.similar.pools import pool_queryset

log = logging.getLogger(__name__)

FORMAT = 2
# An update compacts (retrains and rewrites the generation) once the added and removed
# records outnumber this share of the base: a search compares the query with every added
# vector, and clusters drift as the library changes.
COMPACT_SHARE = 0.05
# ... and never for fewer records than this (a small library would compact at each update).
COMPACT_MIN = 2000
# When the delta (segments newer than the index) grows past this, an update is queued.
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
    try:
        vector_index.check(folder_of(manifest), manifest["state"])
    except (KeyError, TypeError) as exc:
        raise IndexUnusable(f"{path}: no {exc} in it") from exc
    except InputError as exc:
        raise IndexUnusable(str(exc)) from exc
    return manifest


def folder_of(manifest) -> Path:
    return index_dir() / str(manifest["file"])


def _fingerprint(project_id):
    """[count, max id, sum of ids] of the described segments: cheap to compare, and
    changed by any insert or delete."""
    from django.db.models import Count, Max, Sum

    found = described(project_id).aggregate(n=Count("id"), top=Max("id"), total=Sum("id"))
    return [found["n"], found["top"] or 0, int(found["total"] or 0)]


def _publish(project_id, manifest):
    """Replace the project's manifest atomically (written, fsynced, renamed)."""
    manifest = {**manifest, "updated_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
                "bytes": sum(p.stat().st_size for p in folder_of(manifest).iterdir())}
    tmp = manifest_path(project_id).with_suffix(".json.tmp")
    tmp.write_text(json.dumps(manifest, indent=1))
    vector_index.fsync(tmp)
    os.replace(tmp, manifest_path(project_id))
    vector_index.fsync(index_dir())
    return manifest


def _chunks(queryset):
    """(ids, profile vectors, descriptor bytes) of a queryset of described segments,
    READ_CHUNK rows at a time, by id."""
    last = 0
    while True:
        rows = list(queryset.filter(id__gt=last).order_by("id")
                    .values_list("id", "profile", "descriptor")[:READ_CHUNK])
        if not rows:
            return
        last = rows[-1][0]
        missing = [r[0] for r in rows if r[2] is None]
        if missing:
            raise IndexUnusable(f"segments {missing[:5]}: a profile without a descriptor; "
                                "rebuild the library's descriptors")
        yield (np.array([r[0] for r in rows], dtype=np.int64), as_vectors([r[1] for r in rows]),
               [bytes(r[2]) for r in rows])


def _descriptor_rows(blobs, width):
    """(n, width) float32 descriptors from their bytes; IndexUnusable when one differs."""
    sizes = {len(b) for b in blobs}
    if sizes - {4 * width}:
        raise IndexUnusable(f"segment descriptors have {sorted(n // 4 for n in sizes)} numbers, "
                            f"the index {width}; rebuild the library's descriptors")
    return np.frombuffer(b"".join(blobs), dtype="<f4").reshape(len(blobs), width)


def build(project_id):
    """Write a project's index from scratch; returns the manifest (None: nothing to index)."""
    with _locked(project_id):
        return _build(project_id)


def _build(project_id):
    """Read the described segments once, by id: profiles into memory (for training),
    descriptors straight into the payload file (a million are several GB)."""
    fingerprint = _fingerprint(project_id)
    index_dir().mkdir(parents=True, exist_ok=True)
    payload = index_dir() / f"project_{project_id}.payload.tmp"
    id_parts, vector_parts, width = [], [], None
    try:
        with open(payload, "wb") as out:
            for ids, vectors, blobs in _chunks(described(project_id)):
                width = width or len(blobs[0]) // 4
                if id_parts and vectors.shape[1] != vector_parts[0].shape[1]:
                    raise IndexUnusable(f"project {project_id}: segment profiles have "
                                        f"{sorted({vector_parts[0].shape[1], vectors.shape[1]})} "
                                        "numbers; rebuild the library's descriptors")
                out.write(_descriptor_rows(blobs, width).tobytes())
                id_parts.append(ids)
                vector_parts.append(vectors)
        if not id_parts:
            manifest_path(project_id).unlink(missing_ok=True)
            _remove_generations(project_id, keep=None)
            return None
        ids = np.concatenate(id_parts)
        vectors = np.concatenate(vector_parts)
        del id_parts, vector_parts
        generation = time.time_ns()
        name = f"project_{project_id}.g{generation}"
        state = vector_index.build(index_dir() / name, ids, vectors, seed=project_id,
                                   payload=payload, payload_width=width)
    finally:
        payload.unlink(missing_ok=True)
    lists = state.pop("lists")
    manifest = _publish(project_id, {
        "format": FORMAT, "file": name, "generation": generation, "state": state,
        "count": len(ids), "lists": lists, "max_id": int(ids[-1]), "fingerprint": fingerprint,
        "built_at": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())})
    _remove_generations(project_id, keep=name)
    log.info("similar index of project %s built: %s vectors", project_id, manifest["count"])
    return manifest


def _remove_generations(project_id, keep):
    for old in index_dir().glob(f"project_{project_id}.g*"):
        if old.name != keep:
            # Processes that map the old files keep them (unlinked inodes live on).
            shutil.rmtree(old, ignore_errors=True)


def update(project_id):
    """Bring a project's index in step with the database: append the vectors of segments
    it lacks and the keys of deleted ones. Compacts (``build``) when there is no usable
    index, or the appended records would outgrow ``COMPACT_SHARE`` of the base.
    Returns the manifest (unchanged when in step)."""
    with _locked(project_id):
        try:
            manifest = read_manifest(project_id)
            index = vector_index.VectorIndex.open(folder_of(manifest), manifest["state"])
        except (IndexUnusable, InputError) as exc:
            log.info("similar index of project %s rebuilt: %s", project_id, exc)
            return _build(project_id)
        fingerprint = _fingerprint(project_id)
        if fingerprint == manifest.get("fingerprint"):
            return manifest
        keys = index.keys()
        ids = np.fromiter(described(project_id).values_list("id", flat=True).iterator(chunk_size=20000),
                          dtype=np.int64)
        removed = np.setdiff1d(keys, ids, assume_unique=True)
        added = np.setdiff1d(ids, keys, assume_unique=True)
        state = manifest["state"]
        appended = state["delta"] + state["removed"] + len(added) + len(removed)
        if appended > max(COMPACT_MIN, COMPACT_SHARE * state["base"]):
            return _build(project_id)
        add_ids, add_vectors, add_blobs = [], [], []
        for first in range(0, len(added), READ_CHUNK):
            part = [int(i) for i in added[first:first + READ_CHUNK]]
            rows = {pk: (profile, descriptor) for pk, profile, descriptor in LibrarySegment.objects
                    .filter(pk__in=part).values_list("id", "profile", "descriptor")}
            part = [pk for pk in part if pk in rows]  # deleted meanwhile
            add_ids += part
            add_vectors += [rows[pk][0] for pk in part]
            add_blobs += [bytes(rows[pk][1]) for pk in part]
        vectors = as_vectors(add_vectors, index.ndim // similarity.PROFILE_ROWS)
        if len(vectors) and (vectors.shape[1] != index.ndim
                             or {len(b) for b in add_blobs} != {4 * state["payload"]}):
            return _build(project_id)
        payload = _descriptor_rows(add_blobs, state["payload"]) if add_blobs else None
        state = vector_index.append(folder_of(manifest), state, add_ids, vectors, removed,
                                    add_payload=payload)
        max_id = max(int(ids.max()) if len(ids) else 0, manifest["max_id"])
        return _publish(project_id, {**manifest, "state": state, "max_id": max_id,
                                     "count": len(keys) - len(removed) + len(add_ids),
                                     "fingerprint": fingerprint})


def schedule_update(project_id):
    """Queue ``update`` for when the current transaction commits (a worker must see the
    rows). A broker that cannot be reached costs freshness of the file only: searches
    read newer segments from the database."""
    transaction.on_commit(lambda: workers.send(
        "update_similar_index", project_id, then="searches read the newer segments from the database"))


def _candidates_or_newer(pool, ids, project_id, after):
    """``pool``'s rows (a ``pools.Pool``) that are among ``ids`` or newer than ``after``
    (the last segment id of the delta this process has read), in one query: [(id,
    capture, start, stop, profile bytes or None, newest, *SHOWN)]. Only the rows newer
    than ``after`` carry their profile: the others were measured already. ``newest`` is
    the id of the project's newest described segment, whatever the caller may see (the
    next search reads the delta up to it: ``OpenIndex.take_newer``). No descriptor is
    read here (it lives in the database's out-of-line storage, the dearest part of a
    search's queries). ``SHOWN`` is what a result shows of a segment, so the winners need
    no query of their own.

    The newer rows are found by a row comparison on (project, id), so that the database
    walks the ``libseg_described`` index from ``(project, after)`` to the project's end:
    with a plain ``project_id = p AND id > after`` PostgreSQL estimates the project's
    share of all newer rows and often prefers the primary key, then filters every newer
    row of every project. The end is ``project_id <= p``: a second row comparison,
    ``< (p + 1, 0)``, bounds no scan on PostgreSQL 15, which then reads ~80 index pages
    to find nothing (~1 ms at a million). On PostgreSQL the newer ids are an InitPlan
    joined to the candidates' as one array, so the rows themselves are one scan of the
    primary key (an OR of the two lets the planner pick a library-list index and scan the
    project: ~0.5 s at a million), and a ``pools.Scope``'s pool is read through a
    statement compiled once (``CANDIDATE_ROWS``).
    """
    values = {"after": after}
    if connections[pool.db].vendor == "postgresql":
        if pool.scoped:
            return CANDIDATE_ROWS.rows(pool.db, pool.key, ids=ids, **values, **pool.values)
        return list(_candidates_query(pool.key, ids=ids, visible=pool.visible, **values,
                                      **pool.values).using(pool.db))
    table = LibrarySegment._meta.db_table
    where = (f'("{table}"."id" IN ({", ".join(["%s"] * len(ids)) or "NULL"}) '
             f'OR "{table}"."id" IN ({_NEWER}))')
    return list(pool.queryset().extra(where=[where], params=[*ids, project_id, after, project_id])
                .annotate(fresh=_fresh(after), newest=_newest(project_id))
                .values_list(*CANDIDATE_COLUMNS))


# The project's described segments after an id (parameters: project, id, project).
_AFTER = (f'"{LibrarySegment._meta.db_table}" u WHERE u.profile IS NOT NULL'
          ' AND (u.project_id, u.id) > (%s, %s) AND u.project_id <= %s')
_NEWER = f"SELECT u.id FROM {_AFTER}"


def _fresh(after):
    return Case(When(id__gt=after, then=F("profile")), default=None, output_field=BinaryField())


def _newest(project_id):
    """The id of the project's newest described segment, read once per query."""
    return RawSQL(f'(SELECT u.id FROM "{LibrarySegment._meta.db_table}" u WHERE u.profile IS NOT NULL'
                  ' AND u.project_id = %s ORDER BY u.project_id DESC, u.id DESC LIMIT 1)',
                  [project_id], output_field=BigIntegerField())


def _candidates_query(key, ids, after, visible=None, **pool):
    """``_candidates_or_newer``'s query on PostgreSQL, ``ids`` one array parameter."""
    where = f'"{LibrarySegment._meta.db_table}"."id" = ANY(%s::bigint[] || ARRAY({_NEWER}))'
    return (pool_queryset(key, visible=visible, **pool)
            .extra(where=[where], params=[ids, pool["project_id"], after, pool["project_id"]])
            .annotate(fresh=_fresh(after), newest=_newest(pool["project_id"]))
            .values_list(*CANDIDATE_COLUMNS))


# The columns of a segment and its capture, annotator and label that a search result and a
# library list row show (``search.api_fields`` makes the API fields from them).
SHOWN = ("project_id", "review_id", "annotator_id", "is_gold", "superseded", "label_id",
         "duration", "agreement", "capture__name", "capture__fps", "capture__format",
         "annotator__username", "label__name", "label__color")
CANDIDATE_COLUMNS = ("id", "capture_id", "start", "stop", "fresh", "newest", *SHOWN)
CANDIDATE_ROWS = statements.Statement(_candidates_query, lists=("ids",))


@dataclass
class OpenIndex:
    """A project's index as this process sees it: its manifest and the mapped folder, and
    the segments newer than the index (the *delta*) that this process has read.

    The delta's profiles are read once per process (``take_newer``), all of them,
    whatever a caller may see, and each search compares its query with them as with the
    index's: the nearest are candidates like the index's, and the database decides which
    of them exist and may be shown. Each search's candidates query reports the project's
    newest described segment, and the rows newer than what was read come with their
    profiles in that query, so a search costs no query of its own for freshness; the
    next one reads them into the delta. A segment that commits after a newer one was read
    is missed until the index's next update, which its commit queues."""

    project_id: int
    manifest: dict
    index: object
    update_queued: bool = False
    # (mark, ids, profiles): the delta as read, up to segment id ``mark``; the profiles in
    # float64, as every search measures them.
    newer: tuple = None
    _lock: object = field(default_factory=threading.Lock)

    def __post_init__(self):
        if self.newer is None:
            self.newer = (self.manifest["max_id"], np.zeros(0, dtype=np.int64),
                          np.zeros((0, self.index.ndim)))

    def nearest(self, vector, count):
        """Up to ``count`` segment ids of the index nearest to a profile vector, nearest
        first, and their profiles ((n, ndim) float32, as stored). Ids may include segments
        deleted since the last update."""
        ids, _, profiles = self.index.search(vector, count, vectors=True)
        return ids, profiles

    def nearest_newer(self, vector, count):
        """(mark, ids, distances, held): up to ``count`` of the delta's segments nearest to
        ``vector``, their squared distances in float64 (as the exact scan measures), and
        how many the delta holds; ``mark`` the last segment id read."""
        mark, ids, profiles = self.newer
        if not len(ids):
            return mark, ids, np.zeros(0), 0
        diff = profiles - np.asarray(vector, dtype=np.float64)
        d = np.einsum("ij,ij->i", diff, diff)
        near = np.argsort(d, kind="stable")[:count] if len(d) <= count else \
            np.argpartition(d, count - 1)[:count]
        return mark, ids[near], d[near], len(ids)

    def take_newer(self, db, newest):
        """Read the profiles of the project's described segments after the mark, up to id
        ``newest``, into the delta."""
        if newest is None or newest <= self.newer[0]:
            return  # what every search but the first after new segments finds
        with self._lock:
            mark, ids, profiles = self.newer
            if newest <= mark:
                return
            with connections[db].cursor() as cursor:
                cursor.execute(f"SELECT u.id, u.profile FROM {_AFTER} AND u.id <= %s ORDER BY u.id",
                               [self.project_id, mark, self.project_id, newest])
                rows = [(pk, bytes(blob)) for pk, blob in cursor.fetchall()]
            # A profile of another width is left out, as the index leaves it (``update``).
            rows = [(pk, blob) for pk, blob in rows if len(blob) == 4 * self.index.ndim]
            added = np.frombuffer(b"".join(blob for _, blob in rows), dtype="<f4").astype(np.float64)
            self.newer = (newest, np.concatenate([ids, np.array([pk for pk, _ in rows], dtype=np.int64)]),
                          np.concatenate([profiles, added.reshape(len(rows), self.index.ndim)]))

    def note_delta(self, newer):
        """Queue an update (once per manifest) when ``newer`` segments outnumber
        ``DELTA_LIMIT``: every search compares its query with them."""
        if newer > DELTA_LIMIT and not self.update_queued:
            self.update_queued = True
            schedule_update(self.project_id)

    @property
    def size(self):
        return self.manifest["count"]

    def descriptors(self, ids):
        """{id: descriptor (float32, flat)} of those of ``ids`` the index holds."""
        found, payload = self.index.payload(ids)
        return {pk: payload[i] for i, pk in enumerate(ids) if found[i]}


_open = {}
_open_lock = threading.Lock()


def open_index(project_id):
    """The project's usable index for this process, or None (the caller scans exactly).

    The manifest is re-read when it is replaced, so an update is seen at the next search
    (the mapped base is kept while the generation is the same). The first time a process
    sees a generation it checks it against the database; an index that cannot be used
    queues a rebuild.
    """
    try:
        found = manifest_path(project_id).stat()
        stamp = (found.st_ino, found.st_mtime_ns, found.st_size)
    except OSError:
        stamp = None
    with _open_lock:
        current = _open.get(project_id)
        if current is not None and current[0] == stamp:
            opened = current[1]
        else:
            opened = _open_checked(project_id, current[1] if current else None)
            _open[project_id] = (stamp, opened)
    return opened


def _open_checked(project_id, previous=None):
    try:
        manifest = read_manifest(project_id)
        state = manifest["state"]
        if previous is not None and previous.manifest["file"] == manifest["file"]:
            return OpenIndex(project_id, manifest, previous.index.at(state))
        if not state.get("payload"):
            raise IndexUnusable(f"{manifest['file']}: holds no descriptors")
        index = vector_index.VectorIndex.open(folder_of(manifest), state,
                                              in_memory=settings.SIMILAR_INDEX_IN_MEMORY)
        if state["base"] + state["delta"] - state["removed"] != manifest["count"]:
            raise IndexUnusable(f"{manifest['file']}: holds {state['base']} + {state['delta']}"
                                f" - {state['removed']} vectors, the manifest says "
                                f"{manifest['count']}")
        in_db = described(project_id).filter(id__lte=manifest["max_id"]).count()
        if in_db != manifest["count"]:
            # Rows changed since the index was written (a crash before the update, or
            # transactions that committed out of id order): usable, but queue an update.
            log.info("similar index of project %s: %s vectors, %s segments in the database; "
                     "updating", project_id, manifest["count"], in_db)
            schedule_update(project_id)
    except (IndexUnusable, InputError, KeyError, TypeError) as exc:
        if described(project_id).exists():
            log.warning("similar index of project %s not used: %s; rebuilding", project_id, exc)
            schedule_update(project_id)
        return None
    return OpenIndex(project_id, manifest, index)


# The first look at the index asks for CANDIDATES x the shortlist (at least
# MIN_CANDIDATES): the index ranks by the exact profile distance, so only rows the caller
# may not see, or spans seen twice, need the margin. A look that finds too few visible
# ones asks for GROW times as many, up to MAX_CANDIDATES.
CANDIDATES = 2
MIN_CANDIDATES = 48
GROW = 4
MAX_CANDIDATES = 4096


def shortlist(index, query, pool, n):
    """The ``n`` segments of ``pool`` whose profiles are nearest to ``query``'s, nearest
    first, as the exact scan orders them (ties: newest first; one span once), as
    ``[(id, descriptor, row)]``, ``row`` the candidate's columns (``_candidates_or_newer``).

    ``pool`` (a ``pools.Pool``) is what the caller may see of the project; the index
    proposes candidates and ``pool`` decides which exist and may be shown. Returns None
    when even ``MAX_CANDIDATES`` candidates leave fewer than ``n`` (a very selective
    filter): the caller then scans exactly.
    """
    vector = np.asarray(query[:similarity.PROFILE_ROWS], dtype=np.float32).ravel()
    count = max(CANDIDATES * n, MIN_CANDIDATES)
    while True:
        candidates, profiles = index.nearest(vector, count)
        mark, newer, newer_distances, held = index.nearest_newer(vector, count)
        rows = _candidates_or_newer(pool, [*candidates.tolist(), *newer.tolist()],
                                    index.project_id, mark)
        index.take_newer(pool.db, rows[0][5] if rows else newest_id(pool.db, index.project_id))
        index.note_delta(held + sum(r[0] > mark for r in rows))
        measured = dict(zip(candidates.tolist(), _squared(profiles, query).tolist(), strict=True))
        measured.update(zip(newer.tolist(), newer_distances.tolist(), strict=True))
        found = nearest_unique(rows, query, n, measured, index.descriptors)
        exhausted = (len(candidates) < count and count >= index.size) and len(newer) == held
        if len(found) >= n or exhausted:
            return found
        if count >= MAX_CANDIDATES:
            return None
        count *= GROW


def newest_id(db, project_id):
    """The id of the project's newest described segment (None: it has none)."""
    return described(project_id).using(db).order_by("-id").values_list("id", flat=True).first()


def nearest_unique(rows, query, n, measured, stored):
    """The exact scan's order over ``rows`` (id, capture, start, stop, profile bytes or
    None, ...): the ``n`` nearest by profile distance, one row per span (its newest), as
    ``[(id, descriptor, row)]``.

    Every distance is measured as the exact scan measures it (float64), so that ties
    (the same motion in two takes) fall as they do there: a row with a profile from the
    profile, any other from ``measured`` (the index's candidates, from the profiles its
    lists hold, and the delta's). Only the ``n`` chosen rows' descriptors are read: from
    the index (``stored(ids)``), else in one query (a descriptor is 4.9 kB, so reading
    every candidate's would be most of a search's reads). Invalid when a profile or a
    descriptor is not of the query's shape (a library described by another version)."""
    rows = [r for r in rows if r[4] is not None or r[0] in measured]
    if not rows:
        return []
    rows.sort(key=lambda r: -r[0])
    seen, unique = set(), []
    for row in rows:
        if row[1:4] not in seen:
            seen.add(row[1:4])
            unique.append(row)
    width = similarity.PROFILE_ROWS * query.shape[1]
    d = np.array([measured.get(r[0], np.nan) for r in unique])
    fresh = [i for i, r in enumerate(unique) if r[4] is not None]
    if fresh:
        blobs = [bytes(unique[i][4]) for i in fresh]
        if {len(b) for b in blobs} != {4 * width}:
            raise Invalid(f"library profiles have {sorted({len(b) // 4 for b in blobs})} "
                          f"numbers, the query's {width}; rebuild the library")
        d[fresh] = _squared(np.frombuffer(b"".join(blobs), dtype="<f4").reshape(len(fresh), width),
                            query)
    chosen = [unique[i] for i in np.argsort(d, kind="stable")[:n]]
    read = stored([r[0] for r in chosen if r[4] is None])
    newer = [r[0] for r in chosen if r[0] not in read]
    if newer:
        read.update((pk, np.frombuffer(bytes(blob), dtype="<f4")) for pk, blob in
                    LibrarySegment.objects.filter(pk__in=newer).values_list("id", "descriptor"))
    out = []
    for r in chosen:
        descriptor = read.get(r[0])
        if descriptor is None:
            continue  # deleted since the candidates were read
        _check_size(descriptor, query)
        out.append((r[0], descriptor.reshape(query.shape), r))
    return out


def _squared(profiles, query):
    """Squared distances (float64) from each of ``profiles`` (n, width) to ``query``'s
    profile, with float64 differences, as the exact scan measures them."""
    width = similarity.PROFILE_ROWS * query.shape[1]
    if profiles.shape[1] != width:
        raise Invalid(f"library profiles have {profiles.shape[1]} numbers, the query's "
                      f"{width}; rebuild the library")
    diff = np.asarray(profiles, dtype=np.float64) - np.asarray(
        query[:similarity.PROFILE_ROWS], dtype=np.float64).ravel()
    return np.einsum("ij,ij->i", diff, diff)


def _check_size(descriptor, query):
    if descriptor.size != query.size:
        raise Invalid(f"library descriptors have {descriptor.size} numbers, the query's "
                      f"{query.shape[0]} x {query.shape[1]}; rebuild the library")


def forget():
    """Drop this process's open indexes (tests; after a rebuild in the same process)."""
    with _open_lock:
        _open.clear()
