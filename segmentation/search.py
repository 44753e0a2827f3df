"""Similar clips: the library segments that move most like a given one."""

import numpy as np

from motionlib import similarity
from segmentation import similar_index
from segmentation.descriptors import load_descriptors, profile_pool
from segmentation.errors import Invalid
from segmentation.models import LibrarySegment

# Similar clips and suggestions search at most this many of a project's recent segments.
SIMILAR_POOL = 20000
# Profile-nearest segments whose full descriptors are compared (DTW) in both searches.
SHORTLIST = 20


def similar(segment, visible, k=10):
    """The ``k`` visible segments of the same project that move most like ``segment``.

    Segments overlapping it in the same capture are left out (other annotators' versions
    of the same motion), and so are duplicates of one span. Two stages: the profiles
    nearest to the query's pick a shortlist, whose full descriptors are ranked. The
    shortlist comes from the project's vector index (``similar_index``), with the
    shortlisted descriptors read in the same query as the candidates, when it has a
    usable one, else from the profiles of up to ``SIMILAR_POOL`` recent segments.
    Returns ``[(segment, distance)]``, most similar first.
    """
    query = segment.descriptor_array()
    if query is None:
        raise Invalid(f"segment {segment.pk}: its skeleton could not be mapped to body "
                      "parts, so it has no motion descriptor")
    pool = (visible.filter(project_id=segment.project_id, profile__isnull=False)
            .exclude(capture_id=segment.capture_id, start__lt=segment.stop, stop__gt=segment.start))
    n = max(SHORTLIST, k)
    index = similar_index.open_index(segment.project_id)
    short = similar_index.shortlist(index, query, pool, n) if index else None
    if short is None:
        ids = exact_shortlist(query, pool, n)
        short = list(zip(ids, load_descriptors(ids), strict=True)) if ids else []
    if not short:
        return []
    order, distances = similarity.rank_similar(
        query, np.stack([d for _, d in short]), k=k, shortlist=len(short))
    winners = [short[i][0] for i in order]
    # What the caller shows of the winners, in one query (their descriptors are not needed).
    rows = (LibrarySegment.objects.select_related("capture", "annotator", "label")
            .defer("descriptor", "profile", "capture__skeleton").in_bulk(winners))
    # A row deleted since it was shortlisted is left out.
    return [(rows[pk], float(d)) for pk, d in zip(winners, distances, strict=True) if pk in rows]


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
