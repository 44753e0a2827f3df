"""The gate a newly trained cut model passes before it replaces the project's current one.

Both models are scored out of sample on the same reviewed takes: the candidate on each
scored take by a model refitted on the project's other examples (leave-one-take-out,
``motionlib.adapt.Refits``); the current model on a take it did not learn from as it is,
and on a take it learnt from by a refit of its own examples without that take (zero-shot,
the model of a project without one, learnt from nothing). The scored takes fall in two groups, those the
current model learnt from and the others, and the candidate must be not worse in each:
an annotator whose new reviews cut differently from everyone before makes a candidate
that wins on their own takes and loses on the others', and such a model is refused.
The rule and its reasons: docs/learning.md.
"""

import dataclasses

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

    def not_worse_than(self, other):
        """No more edits per true cut (equal is not worse), and an F1 at most F1_MARGIN
        lower."""
        return (self.edits_per_cut <= other.edits_per_cut + 1e-9
                and self.f1 >= other.f1 - F1_MARGIN - 1e-9)

    def text(self):
        return f"{self.edits_per_cut:.2f} edits per true cut (F1 {self.f1:.2f})"


@dataclasses.dataclass
class Verdict:
    """The candidate's own held-out figure, and why it is refused ("" when accepted)."""

    figure: Figure
    refused: str


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


def judge(examples, current, current_model, *, candidate_without, current_without, detect):
    """Score the candidate fitted on ``examples`` against the project's current model.

    Parameters
    ----------
    examples : [(capture, cuts)], the examples the candidate learnt from.
    current : the project's current ProjectCutModel row, or None (zero-shot).
    current_model : its loaded CutModel, or None (zero-shot, or unreadable).
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
    figure = Figure()
    groups = {True: (Figure(), Figure()), False: (Figure(), Figure())}  # learnt: (new, current)
    for capture, cuts in scored_takes(examples, learnt):
        candidate = candidate_without(capture)
        was_learnt = capture.pk in learnt
        rival = current_without(capture) if was_learnt else current_model
        found = detect(capture, candidate)
        rival_found = found if rival == candidate else detect(capture, rival)
        figure.add(found, cuts, capture.fps)
        groups[was_learnt][0].add(found, cuts, capture.fps)
        groups[was_learnt][1].add(rival_found, cuts, capture.fps)
    reasons = [_reason(new, old, was_learnt, current)
               for was_learnt, (new, old) in groups.items()
               if new.takes and not new.not_worse_than(old)]
    return Verdict(figure, "refused: " + "; ".join(reasons) if reasons else "")


def _reason(new, old, was_learnt, current):
    """Why the candidate lost on one group of takes, with both figures."""
    takes = f"{new.takes} held-out reviewed take{'s' if new.takes != 1 else ''}"
    if current is None:
        return f"on {takes} it needs {new.text()}, the zero-shot detector {old.text()}"
    whose = "learnt from" if was_learnt else "did not learn from"
    return (f"on {takes} that the current model v{current.version} {whose} it needs "
            f"{new.text()}, the current model {old.text()}")
