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
- ``updates.update`` (a Celery task queued when library rows change, and run by
  ``manage.py similar_index``) compares the index's keys with the database's ids and
  appends the difference: it writes the added vectors and removed keys, not the index.
  When the appended records outgrow ``COMPACT_SHARE`` of the base, or there is no usable
  index, it *compacts*: ``updates.build`` trains new centres over the whole library and writes a
  new generation beside the old one before naming it (processes that still map the old
  one keep reading it until they see the new manifest).
- ``open_index`` checks a manifest the first time a process sees a generation: a missing
  or short file, another format or width, or a vector count that disagrees with the
  database all mean "not usable": the search falls back to the exact scan and a rebuild
  is queued.

This module holds the index as a process has it open (``open_index``, ``OpenIndex``);
``similar.files`` the folder and manifest, ``similar.updates`` ``build`` and ``update``,
and ``similar.candidates`` the search of candidates through an open index.
"""

import logging
import threading
from dataclasses import dataclass, field

import numpy as np
from django.conf import settings
from django.db import connections

from motionlib import vector_index
from motionlib.errors import InputError
from segmentation.models import LibrarySegment
from segmentation.similar.files import (
    IndexUnusable,
    described,
    folder_of,
    manifest_path,
    read_manifest,
)
from segmentation.similar.updates import schedule_update

log = logging.getLogger(__name__)

# When the delta (segments newer than the index) grows past this, an update is queued.
DELTA_LIMIT = 5000

# The project's described segments after an id (parameters: project, id, project).
AFTER = (f'"{LibrarySegment._meta.db_table}" u WHERE u.profile IS NOT NULL'
          ' AND (u.project_id, u.id) > (%s, %s) AND u.project_id <= %s')


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
                cursor.execute(f"SELECT u.id, u.profile FROM {AFTER} AND u.id <= %s ORDER BY u.id",
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



def forget():
    """Drop this process's open indexes (tests; after a rebuild in the same process)."""
    with _open_lock:
        _open.clear()
