"""Candidate search: the segments a similar-clip search measures, proposed by a project's
open index (``segmentation.similar.index``) and read from the database in one query,
which decides which of them exist and the caller may see."""

import numpy as np
from django.db import connections
from django.db.models import BigIntegerField, BinaryField, Case, F, When
from django.db.models.expressions import RawSQL

from motionlib import similarity
from segmentation.db import statements
from segmentation.errors import Invalid
from segmentation.models import LibrarySegment
from segmentation.similar.files import described
from segmentation.similar.index import AFTER
from segmentation.similar.pools import pool_queryset


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


_NEWER = f"SELECT u.id FROM {AFTER}"


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
