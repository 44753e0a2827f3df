"""The cuts several annotators agree on: one example per reviewed take, made from all of
its submitted reviews, so that no single annotator decides what the project learns.

Plain Python, no Django: the service passes each review's kept cut frames.
The rule and why it was chosen: docs/learning.md.
"""

import bisect
import heapq

# A referee's vote: less than one annotator's, so it only settles ties between them.
REFEREE_VOTE = 0.5


def consensus_cuts(reviews, tolerance, referee=None):
    """Cuts supported by at least half of ``reviews``, each at the median of its support.

    Parameters
    ----------
    reviews : sequence of sequences of int, each review's kept cut frames (0-based).
    tolerance : frames two annotators' cuts may lie apart and still mean the same cut.
    referee : sequence of int or None, cut frames of a voter that belongs to no annotator
        (the service passes what the project's current model, or the zero-shot detector,
        proposes on the take). It has REFEREE_VOTE, half an annotator's: it never outvotes
        an annotator, and it settles a tie between them (two annotators, one of whom
        under- or over-cut the take) for whichever side the project agreed on before. Its
        cuts seed nothing and never place a cut; ignored with fewer than two reviews.

    Returns
    -------
    list of int, sorted unique frames. One review gives its own cuts; none gives [].

    A consensus cut gathers at most one cut of each review, the one nearest to a seed (a
    cut some review made) within ``tolerance``; each review's cut serves one consensus
    cut. Seeds with the most support are taken first (ties: the earlier frame). A cut
    supported by exactly half of the reviews is kept: with two annotators, one of them
    leaving out a cut the other made cannot remove it (an under-cutting annotator is what
    starved the learnt model of candidates). The median of an even number of cuts is the
    lower middle one, so a consensus cut is always a frame some annotator chose.
    """
    cuts = [sorted({int(f) for f in review}) for review in reviews]
    if len(cuts) <= 1:
        return cuts[0] if cuts else []
    free = [list(c) for c in cuts]  # each review's cuts not yet used, sorted
    votes = [1.0] * len(cuts)
    if referee is not None:
        free.append(sorted({int(f) for f in referee}))
        votes.append(REFEREE_VOTE)
    total = sum(votes)
    heap = [(-_support(free, votes, seed, tolerance), seed) for seed in sorted({f for c in cuts for f in c})]
    heapq.heapify(heap)
    kept = set()
    while heap:
        negative, seed = heapq.heappop(heap)
        support = _support(free, votes, seed, tolerance)
        if support != -negative:  # cuts were used since: look again at its true place
            heapq.heappush(heap, (-support, seed))
            continue
        if 2 * support < total:
            break  # supports only shrink: nothing after this one reaches half either
        chosen = [_take_nearest(review, seed, tolerance) for review in free]
        # The referee's cut is used up, but the cut is placed among the annotators' own.
        chosen = sorted(f for f in chosen[:len(cuts)] if f is not None)
        kept.add(chosen[(len(chosen) - 1) // 2])
    return sorted(kept)


def _nearest(review, seed, tolerance):
    """Index of the cut of ``review`` (sorted) nearest to ``seed`` within ``tolerance``
    (the earlier one on a tie), or None."""
    i = bisect.bisect_left(review, seed)
    best = None
    for j in (i - 1, i):
        if 0 <= j < len(review) and abs(review[j] - seed) <= tolerance:
            if best is None or abs(review[j] - seed) < abs(review[best] - seed):
                best = j
    return best


def _support(free, votes, seed, tolerance):
    """The votes of the reviews that still have a free cut within ``tolerance`` of ``seed``."""
    return sum(vote for review, vote in zip(free, votes, strict=True)
               if _nearest(review, seed, tolerance) is not None)


def _take_nearest(review, seed, tolerance):
    """Remove and return the cut of ``review`` nearest to ``seed``, or None."""
    j = _nearest(review, seed, tolerance)
    return None if j is None else review.pop(j)
