"""The gate a newly trained cut model passes before it replaces the project's current one.

Both models are scored out of sample on the same reviewed takes: the candidate on each
scored take by a model refitted on the project's other examples (leave-one-take-out,
``motionlib.adapt.Refits``); the current model on a take it did not learn from as it is,
and on a take it learnt from by a refit of its own examples without that take (zero-shot,
the model of a project without one, learnt from nothing). The candidate must propose a
plausible number of cuts beside the zero-shot detector (``Count``), and the scored takes
are compared by source (``_source_reasons``): worse on gold versions or on takes several
annotators reviewed refuses it; one annotator's own takes are one capped vote, so a lone
annotator can neither get a model accepted nor refused against the rest of the project.
The rule and its reasons: docs/learning.md.
"""

import dataclasses
from collections import defaultdict

from motionlib import metrics

# Takes scored per training, most recently uploaded first: each costs up to two refits
# from the stored studies and two choices among its stored candidates.
FOLDS = 10
# Within this many seconds a candidate matches a true cut, for F1 and for review edits.
TOLERANCE_S = 1.0
# How much lower a candidate's F1 may be than the current model's when it needs no more
# review edits: edits decide (they are what review costs, and they count a cut placed
# further than a snap from the true one, which F1 at 1 s does not), F1 only guards
# against a model that buys fewer edits with many more missed or extra cuts.
F1_MARGIN = 0.05
# A candidate proposing fewer than 1/COUNT_FACTOR or more than COUNT_FACTOR times the
# zero-shot detector's cuts on the scored takes is refused, whatever its figure: a model
# that proposes nothing scores perfectly on takes whose reviews keep no cut.
COUNT_FACTOR = 4.0
# Where a scored take's example came from (else the id of the one annotator who reviewed
# it): a reviewer's gold version, or the consensus of two or more annotators' reviews.
GOLD = "gold"
SHARED = "shared"
LABELS = {GOLD: "with a gold version", SHARED: "reviewed by several annotators"}
# In ``sources``: the annotators whose takes keep far fewer or more cuts than the zero-shot
# detector proposes there (``adaptation.implausible``); their takes have no say here.
IMPLAUSIBLE = "implausible"


@dataclasses.dataclass
class Figure:
    """A model's review cost, summed over scored takes: edits per true cut and F1 are
    pooled over all their cuts, so a take with few cuts weighs less than one with many."""

    takes: int = 0
    edits: int = 0
    true_cuts: int = 0
    candidates: int = 0
    matched: int = 0

    def add(self, candidates, truth, fps):
        cost = metrics.edit_cost(candidates, truth, fps=fps, match_s=TOLERANCE_S)
        scores = metrics.boundary_scores(candidates, truth, fps=fps, tolerance_s=TOLERANCE_S)
        self.takes += 1
        self.edits += cost["edits"]
        self.true_cuts += len(truth)
        self.candidates += len(candidates)
        self.matched += scores["matched"]

    @property
    def edits_per_cut(self):
        """Review edits per true cut (edits themselves when no take has a true cut)."""
        return self.edits / self.true_cuts if self.true_cuts else float(self.edits)

    @property
    def f1(self):
        precision = self.matched / self.candidates if self.candidates else 1.0
        recall = self.matched / self.true_cuts if self.true_cuts else 1.0
        total = precision + recall
        return 2 * precision * recall / total if total else 0.0

    def merge(self, other):
        for field in dataclasses.fields(self):
            setattr(self, field.name, getattr(self, field.name) + getattr(other, field.name))

    def not_worse_than(self, other):
        """No more edits per true cut (equal is not worse), and an F1 at most F1_MARGIN
        lower."""
        return (self.edits_per_cut <= other.edits_per_cut + 1e-9
                and self.f1 >= other.f1 - F1_MARGIN - 1e-9)

    def text(self):
        return f"{self.edits_per_cut:.2f} edits per true cut (F1 {self.f1:.2f})"


@dataclasses.dataclass
class Verdict:
    """The candidate's own held-out figure, why it is refused ("" when accepted), and what
    the figure was measured on (``basis``)."""

    figure: Figure
    refused: str
    basis: dict


class FoldStudies:
    """``motionlib.adapt.Studies`` for the refits: reads each stored study once and keeps it,
    and what the refits make, in memory (every refit reads the studies of all the other
    takes). A refit without the take holding the project's shortest segment learns with
    other settings; storing its studies would replace the ones the full fit stored (one
    per take) and cost the next training a new analysis of each take."""

    def __init__(self, stored):
        self.stored = stored
        self.made = {}

    def load(self, example_key, study_key):
        key = (example_key, study_key)
        if key not in self.made and self.stored is not None:
            self.made[key] = self.stored.load(example_key, study_key)
        return self.made.get(key)

    def save(self, example_key, study_key, arrays):
        self.made[(example_key, study_key)] = arrays


def scored_takes(examples, learnt):
    """The examples to score, at most FOLDS: half of them taken from the takes the current
    model did not learn from, half from those it did, most recently uploaded first; a group
    with fewer takes leaves its places to the other. Both groups are scored whenever both
    exist, since the gate compares the models in each."""
    newest_first = sorted(examples, key=lambda e: e[0].pk, reverse=True)
    new = [e for e in newest_first if e[0].pk not in learnt]
    old = [e for e in newest_first if e[0].pk in learnt]
    n_new = min(len(new), max(FOLDS // 2, FOLDS - len(old)))
    return new[:n_new] + old[:FOLDS - n_new]


def judge(examples, current, current_model, *, sources, candidate_without, current_without, detect):
    """Score the candidate fitted on ``examples`` against the project's current model.

    Parameters
    ----------
    examples : [(capture, cuts)], the examples the candidate learnt from.
    current : the project's current ProjectCutModel row, or None (zero-shot).
    current_model : its loaded CutModel, or None (zero-shot, or unreadable).
    sources : {capture id: GOLD, SHARED or the id of the one annotator who reviewed it}.
    candidate_without : capture -> the candidate refitted without that example (None:
        zero-shot, when it was the only one).
    current_without : capture -> the current model refitted on its own examples without
        that one (None: zero-shot); asked only for takes the current model learnt from.
    detect : (capture, CutModel or None) -> candidate cut frames in its take.

    Returns
    -------
    Verdict.
    """
    learnt = set(current.trained_on) if current is not None else set()
    figure, count = Figure(), Count()
    groups = defaultdict(lambda: (Figure(), Figure()))  # source: (candidate, current)
    for capture, cuts in scored_takes(examples, learnt):
        candidate = candidate_without(capture)
        rival = current_without(capture) if capture.pk in learnt else current_model
        found = detect(capture, candidate)
        rival_found = found if rival == candidate else detect(capture, rival)
        zero_found = found if candidate is None else rival_found if rival is None else detect(capture, None)
        figure.add(found, cuts, capture.fps)
        count.add(found, zero_found)
        new, old = groups[sources.get(capture.pk, SHARED)]
        new.add(found, cuts, capture.fps)
        old.add(rival_found, cuts, capture.fps)
    whose = "the zero-shot detector" if current is None else f"the current model v{current.version}"
    reasons = [*count.reasons(), *_source_reasons(groups, whose, sources.get(IMPLAUSIBLE, frozenset()))]
    return Verdict(figure, "refused: " + "; ".join(reasons) if reasons else "", basis(groups, figure))


@dataclasses.dataclass
class Count:
    """How many cuts the candidate proposes on the scored takes beside the zero-shot
    detector, counted on the takes where the zero-shot detector proposes any."""

    takes: int = 0
    proposed: int = 0
    zero_shot: int = 0

    def add(self, found, zero_found):
        if len(zero_found):
            self.takes += 1
            self.proposed += len(found)
            self.zero_shot += len(zero_found)

    def reasons(self):
        """Why the count alone refuses the candidate: none at all, or outside
        [zero-shot / COUNT_FACTOR, zero-shot x COUNT_FACTOR]."""
        if not self.takes or self.zero_shot / COUNT_FACTOR <= self.proposed <= self.zero_shot * COUNT_FACTOR:
            return []
        takes = f"{self.takes} held-out reviewed take{'s' if self.takes != 1 else ''}"
        return [f"it proposes {self.proposed} cut{'s' if self.proposed != 1 else ''} on {takes} where the "
                f"zero-shot detector proposes {self.zero_shot} (a model must propose between a quarter "
                f"and {COUNT_FACTOR:g} times as many)"]


def _source_reasons(groups, whose, implausible):
    """Why the candidate loses where it is compared by source: on the gold versions, on
    the takes several annotators reviewed, or on the takes one annotator alone reviewed
    when those outweigh the takes where it is not worse. Each annotator's takes weigh at
    most as much as all other scored takes (ties refuse: the current model stays); an
    implausible annotator's weigh nothing."""
    worse = {source: not new.not_worse_than(old) for source, (new, old) in groups.items()}
    reasons = [_reason(*groups[source], LABELS[source], whose)
               for source in (GOLD, SHARED) if worse.get(source)]
    total = sum(new.takes for new, _old in groups.values())
    weight = {source: new.takes if source in (GOLD, SHARED) else min(new.takes, total - new.takes) or new.takes
              for source, (new, _old) in groups.items()}
    for source in implausible:
        weight[source] = 0
    if groups and not any(weight.values()):
        n = sum(new.takes for new, _old in groups.values())
        return [f"its {n} held-out take{'s' if n != 1 else ''} were all reviewed by annotators whose "
                f"reviews keep far fewer or far more cuts than the zero-shot detector proposes there"]
    lose = sum(weight.get(s, 0) for s in groups if worse[s] and s not in (GOLD, SHARED))
    win = sum(weight.get(s, 0) for s in groups if not worse[s])
    if lose and lose >= win:
        new, old = Figure(), Figure()
        losing = [s for s in groups if worse[s] and s not in (GOLD, SHARED) and weight.get(s)]
        for source in losing:
            new.merge(groups[source][0])
            old.merge(groups[source][1])
        who = "one annotator alone" if len(losing) == 1 else f"one annotator each ({len(losing)} annotators)"
        reasons.append(_reason(new, old, f"reviewed by {who}", whose)
                       + (", and the takes where it is not worse do not outweigh them" if win else ""))
    return reasons


def _reason(new, old, what, whose):
    """Why the candidate lost on one group of takes, with both figures."""
    takes = f"{new.takes} held-out take{'s' if new.takes != 1 else ''} {what}"
    return f"on {takes} it needs {new.text()}, {whose} {old.text()}"


def basis(groups, figure):
    """What the figure was measured on, for the review page: scored takes with a gold
    version, reviewed by several annotators, reviewed by one annotator alone (and how many
    such annotators), and the true cuts among them."""
    lone = [s for s in groups if s not in (GOLD, SHARED)]
    return {"gold": groups[GOLD][0].takes if GOLD in groups else 0,
            "shared": groups[SHARED][0].takes if SHARED in groups else 0,
            "single": sum(groups[s][0].takes for s in lone), "annotators": len(lone),
            "true_cuts": figure.true_cuts}
