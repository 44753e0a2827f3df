"""Similar clips: the library segments that move most like a given one."""

from types import SimpleNamespace

import numpy as np

from motionlib import similarity
from segmentation.errors import Invalid
from segmentation.files import exports
from segmentation.models import LibrarySegment
from segmentation.similar import candidates, index
from segmentation.similar.descriptors import load_descriptors, profile_pool
from segmentation.similar.pools import Pool

# Similar clips and suggestions search at most this many of a project's recent segments.
SIMILAR_POOL = 20000
# Profile-nearest segments whose full descriptors are compared (DTW) in both searches.
SHORTLIST = 20


def similar(segment, visible, k=10):
    """The ``k`` visible segments of the same project that move most like ``segment``.

    ``visible``: a queryset of the segments the caller may see, or a ``pools.Scope``
    (the same, read on PostgreSQL through statements compiled once: ``statements``).
    Only segments described as it is are compared (``descriptors.same_kind``: a body or
    bare points). Segments overlapping it in the same capture are left out (other
    annotators' versions of the same motion), and so are duplicates of one span. Two
    stages: the profiles nearest to the query's pick a shortlist, whose full descriptors
    are ranked. The shortlist comes from the project's
    vector index (``similar.index``, which keeps the descriptors too) when it has a usable
    one, else from the profiles of up to ``SIMILAR_POOL`` recent segments.
    Returns ``[(segment, distance)]``, most similar first; a segment found through the
    index is a ``Shown`` (its id and its API fields), one from the exact scan a
    LibrarySegment.
    """
    query = segment.descriptor_array()
    if query is None:
        raise Invalid(f"segment {segment.pk}: its skeleton could not be mapped to body "
                      "parts and it is not a take of points, so it has no motion descriptor")
    pool = Pool(segment, visible)
    n = max(SHORTLIST, k)
    opened = index.open_index(segment.project_id)
    short = candidates.shortlist(opened, query, pool, n) if opened else None
    if short is None:
        ids = exact_shortlist(query, pool.queryset(), n)
        short = list(zip(ids, load_descriptors(ids), [None] * len(ids), strict=True))
    if not short:
        return []
    order, distances = similarity.rank_similar(
        query, np.stack([d for _, d, _ in short]), k=k, shortlist=len(short))
    winners = [short[i] for i in order]
    if all(row is not None for _, _, row in winners):
        return [(shown(row), float(d)) for (_, _, row), d in zip(winners, distances, strict=True)]
    # The exact scan read no display columns: the winners' rows in one query.
    rows = (LibrarySegment.objects.select_related("capture", "annotator", "label")
            .defer("descriptor", "profile", "capture__skeleton").in_bulk([pk for pk, _, _ in winners]))
    # A row deleted since it was shortlisted is left out.
    return [(rows[pk], float(d)) for (pk, _, _), d in zip(winners, distances, strict=True)
            if pk in rows]


class Shown:
    """A result read from the candidates' columns: its id and what the API shows of it
    (``SegmentSerializer``'s fields, made without model instances: a search shows ten, and
    building a segment, capture, label and user for each cost more than the ranking)."""

    __slots__ = ("pk", "data")

    def __init__(self, pk, data):
        self.pk, self.data = pk, data


def shown(row):
    """``Shown`` from a candidate row of ``similar.candidates`` (``CANDIDATE_COLUMNS``)."""
    pk, capture_id, start, stop = row[:4]
    return Shown(pk, api_fields(pk, capture_id, start, stop, row[6:]))


def api_fields(pk, capture_id, start, stop, columns):
    """What the API shows of a segment (``SegmentSerializer``'s fields) from its id,
    capture, frames and its ``candidates.SHOWN`` columns."""
    f = dict(zip(candidates.SHOWN, columns, strict=True))
    return {
        "id": pk, "project": f["project_id"],
        "capture": {"id": capture_id, "name": f["capture__name"]}, "review": f["review_id"],
        "annotator": ({"id": f["annotator_id"], "username": f["annotator__username"]}
                      if f["annotator_id"] else None),
        "gold": f["is_gold"], "superseded": f["superseded"], "label": f["label__name"],
        "color": f["label__color"] if f["label_id"] else "#888888", "start": start,
        "stop": stop, "fps": float(f["capture__fps"]), "duration": float(f["duration"]),
        "agreement": None if f["agreement"] is None else float(f["agreement"]),
        "export_formats": exports.formats_for(SimpleNamespace(format=f["capture__format"]))}


def exact_shortlist(query, pool, n):
    """Ids of the ``n`` profile-nearest segments among the ``SIMILAR_POOL`` most recent of
    ``pool`` (one span counted once, its newest row kept), nearest first."""
    rows = pool.order_by("-id").values_list("id", "capture_id", "start", "stop", "profile")
    seen, unique = set(), []
    for pk, capture_id, start, stop, blob in rows[:SIMILAR_POOL]:
        if (capture_id, start, stop) not in seen:
            seen.add((capture_id, start, stop))
            unique.append((pk, blob))
    ids, profiles = profile_pool(unique, query.shape[1])
    if not ids:
        return []
    return [ids[i] for i in similarity.shortlist_by_profile(query, profiles, n)]
