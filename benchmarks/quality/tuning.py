"""Choosing the default detector's settings honestly: leave-one-take-out.

The zero-shot defaults of ``motionlib.segmenters.default`` are chosen from :data:`GRID`, a
small set of principled options, by the best mean score over labelled takes. To know how
that *choice* does on a take it has not seen, :meth:`Selection.leave_one_out` repeats it
without each take (and without every other view of the same take, e.g. the four-channel
extract of a full AMC) and scores the result on the take left out; :func:`by_source`
does the same with a whole label source left out.

The score of a setting over some takes is the mean F1 at 1 s, ties broken by fewer edits
per true cut (``motionlib.metrics``); :func:`edits_objective` is the other order, scored
beside it. Options tried and not shipped (:data:`TRIED`) are scored the same way, with the
choice made from :func:`tried_grid`, so that the record of why they are not shipped can be
re-run (``python -m benchmarks quality``). How the objective and the grid were
settled is in ``docs/detector/tuning.md``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from benchmarks.quality.tried import Tried, detector
from motionlib import metrics
from motionlib.segmenters.default import shipped_stage

# The options the defaults are chosen from. Windows: (shortest, longest) in seconds.
GRID = {
    "windows": ((1.5, 3.0), (1.5, 6.0), (2.0, 4.0), (3.0, 6.0)),
    "threshold": (0.1, 0.15, 0.2, 0.25, 0.3),
    "prominence": (0.0, 0.05, 0.1, 0.15),
    "min_segment_s": (1.5, 2.0),
    "onset": (False, True),
    "short_unmatched": (0.0, 1.0),
    "support": (0.0, 0.25, 0.5, 1.0),
}

# Options of ``tried.Tried`` scored out of sample beside GRID but not shipped
# (``docs/detector/`` says why each is not). Each setting's default, off, stays an option.
TRIED = {
    "short_activity": (4.0, 8.0),
    "short_uniformity": (0.2, 0.3),
    "tempo": (True,),
}


def tried_grid() -> dict:
    """:data:`GRID` with each :data:`TRIED` setting's shipped value and tried options."""
    return {**GRID, **{key: (Tried.params[key].default, *values)
                       for key, values in TRIED.items()}}


def grid_choices(grid: dict | None = None) -> list[dict]:
    """Every combination of :data:`GRID` as ``default`` segmenter parameters."""
    grid = grid or GRID
    keys = list(grid)
    out = []
    for values in itertools.product(*(grid[k] for k in keys)):
        choice = dict(zip(keys, values, strict=True))
        if "windows" in choice:
            choice["scale_min_s"], choice["scale_max_s"] = choice.pop("windows")
        out.append(choice)
    return out


# Settings that move cuts but do not change which peaks become cuts.
PLACEMENT_ONLY = frozenset({"onset", "refine_s"})


@dataclass
class TakeCache:
    """One labelled take read once, with its novelty analyses by window setting.

    A ``pool`` take is labelled material that settings are chosen on (and a model adapted
    to) but that is not scored itself (the bench's ``--pool``).
    """

    labelled: object  # data.LabelledTake
    take: object
    pool: bool = False
    analyses: dict = field(default_factory=dict)
    peaks: dict = field(default_factory=dict)
    placed: dict = field(default_factory=dict)
    scores: dict = field(default_factory=dict)

    @property
    def key(self) -> str:
        """Takes sharing a name are views of one capture and are left out together."""
        return self.labelled.name

    def analysis(self, p: dict):
        windows = (p["scale_min_s"], p["scale_max_s"], p["bandwidth"], p["rate_hz"],
                   p["velocity_s"], p.get("tempo", False))
        if windows not in self.analyses:
            self.analyses[windows] = detector(p).analyse(self.take, p)
        return self.analyses[windows]

    def cuts(self, params: dict) -> np.ndarray:
        """The default detector's cuts with ``params`` (0-based take frames)."""
        method = detector(params)
        p = method.validate_params(params)
        a = self.analysis(p)
        if a is None:
            return np.zeros(0, dtype=np.int64)
        chosen = (id(a), *sorted((k, v) for k, v in p.items() if k not in PLACEMENT_ONLY))
        if chosen not in self.peaks:
            self.peaks[chosen] = method.peaks(a, p)
        found = self.peaks[chosen]
        key = (id(a), p["refine_s"], tuple(found.samples))
        if key not in self.placed:
            self.placed[key] = method.place(a, found, p).stages
        return self.placed[key][shipped_stage(p)] + a.first

    def score(self, params: dict) -> dict:
        """``metrics.evaluate`` of the cuts with ``params`` (computed once per set of cuts:
        many choices of a grid make the same cuts)."""
        cuts = self.cuts(params)
        key = tuple(cuts.tolist())
        if key not in self.scores:
            self.scores[key] = metrics.evaluate(cuts, self.labelled.truth, fps=self.take.fps)
        return dict(self.scores[key])


def score_rows(cache: Sequence[TakeCache], params: dict) -> list[dict]:
    """``metrics.evaluate`` of ``params`` on each take."""
    return [c.score(params) for c in cache]


def objective(rows: Sequence[dict]) -> tuple[float, float]:
    """Higher is better: mean F1@1 s, then fewer edits per true cut."""
    return (round(float(np.mean([r["f1@1s"] for r in rows])), 9),
            -round(float(np.mean([r["edits_per_cut"] for r in rows])), 9))


def edits_objective(rows: Sequence[dict]) -> tuple[float, float]:
    """Tried, not shipped: fewer edits per true cut, then mean F1@1 s (how it scored:
    ``docs/detector/tuning.md``)."""
    f1, edits = objective(rows)
    return edits, f1


@dataclass
class Selection:
    """Scores of every choice on every take: ``rows[i][j]`` is choice i on take j."""

    choices: list[dict]
    cache: list[TakeCache]
    rows: list[list[dict]]

    def shipped(self) -> Selection:
        """The choices of the shipped grid (:data:`GRID`) inside one made from
        :func:`tried_grid`: each :data:`TRIED` setting at its default (off), left out of
        the choice, so that it is a setting of the shipped detector."""
        shipped = self.subset(**{key: Tried.params[key].default for key in TRIED})
        choices = [{k: v for k, v in ch.items() if k not in TRIED} for ch in shipped.choices]
        return Selection(choices, shipped.cache, shipped.rows)

    def subset(self, **fixed) -> Selection:
        """The choices whose settings equal ``fixed`` (e.g. the shipped grid inside
        :func:`tried_grid`), with their scores."""
        idx = [i for i, ch in enumerate(self.choices)
               if all(_value(ch, key) == value for key, value in fixed.items())]
        return Selection([self.choices[i] for i in idx], self.cache, [self.rows[i] for i in idx])

    def best(self, keep: Sequence[bool], score=None) -> int | None:
        """Index of the best choice by ``score`` (default :func:`objective`) on the takes
        where ``keep`` is true (None when there is no such take: nothing to choose on)."""
        if not any(keep):
            return None
        score = score or objective
        scores = [score([r for r, k in zip(rows, keep, strict=True) if k])
                  for rows in self.rows]
        return max(range(len(scores)), key=lambda i: scores[i])

    def chosen(self) -> dict:
        """The choice on every take: the shipped default."""
        return self.choices[self.best([True] * len(self.cache))]

    def leave_one_out(self, score=None) -> list[tuple[dict, dict] | None]:
        """Per take: the choice made without it (and its other views) by ``score``
        (default :func:`objective`), and its row there; None for a take with no other
        capture to choose on."""
        return self._chosen_without(lambda other, c: other.key != c.key, score)

    def leave_source_out(self) -> list[tuple[dict, dict] | None]:
        """Per take: the choice made on the takes of the other label sources only, and its
        row there; None when every take has the same source."""
        return self._chosen_without(
            lambda other, c: other.labelled.source != c.labelled.source)

    def _chosen_without(self, usable, score=None) -> list[tuple[dict, dict] | None]:
        """Per take ``c``: the best choice on the takes ``other`` where ``usable(other, c)``,
        and its row on ``c``."""
        out = []
        for j, c in enumerate(self.cache):
            i = self.best([usable(other, c) for other in self.cache], score)
            out.append(None if i is None else (self.choices[i], self.rows[i][j]))
        return out


def select(cache: Sequence[TakeCache], choices: list[dict] | None = None) -> Selection:
    """Score every choice (default: the whole :data:`GRID`) on every take."""
    choices = grid_choices() if choices is None else choices
    return Selection(choices, list(cache), [score_rows(cache, ch) for ch in choices])


def _value(choice: dict, key: str):
    """A choice's value of a setting of the grid (the shipped value if it sets none)."""
    if key == "windows":
        return (choice["scale_min_s"], choice["scale_max_s"])
    return choice[key] if key in choice or key not in Tried.params \
        else Tried.params[key].default


def out_of_sample(selection: Selection, grid: dict | None = None) -> list[tuple[str, object,
                                                                                 float, float]]:
    """How each option of each setting scores out of sample.

    For every setting and every value it can take, the leave-one-take-out mean F1@1 s and
    edits per true cut when that value is imposed and the other settings are still chosen
    on the other takes; the mean is over the takes scored (not ``pool``) that have another
    capture to choose on.

    Returns
    -------
    list of (setting, value, mean F1@1 s, mean edits per true cut).
    """
    grid = grid or GRID
    return [(key, value, *_loo_means(selection.subset(**{key: value})))
            for key, values in grid.items() for value in values]


def objectives(selection: Selection) -> list[tuple[str, float, float]]:
    """The leave-one-take-out mean F1@1 s and edits per true cut when every choice is
    made by the shipped :func:`objective` and by :func:`edits_objective`."""
    return [(name, *_loo_means(selection, score)) for name, score in
            (("F1@1s first", objective), ("edits first", edits_objective))]


def by_source(selection: Selection) -> list[tuple[str, int, dict, dict]]:
    """How the choice transfers between label sources: per source, its number of scored
    takes (not ``pool``), and their mean row (F1@1 s, edits per true cut, median error)
    when the settings are chosen on the other sources only and leave-one-take-out."""
    out = []
    sources = dict.fromkeys(c.labelled.source for c in selection.cache if not c.pool)
    ways = (selection.leave_source_out(), selection.leave_one_out())
    for source in sources:
        means = []
        for chosen in ways:
            rows = _scored_rows(chosen, selection.cache, source)
            means.append({key: _mean([r[key] for r in rows]) for key in
                          ("f1@1s", "edits_per_cut", "median_error_s")})
        n = sum(not c.pool and c.labelled.source == source for c in selection.cache)
        out.append((source, n, *means))
    return out


def _loo_means(selection: Selection, score=None) -> tuple[float, float]:
    """Mean F1@1 s and edits per true cut, leave-one-take-out, over the takes scored (not
    ``pool``) that have another capture to choose on."""
    rows = _scored_rows(selection.leave_one_out(score), selection.cache)
    return _mean([r["f1@1s"] for r in rows]), _mean([r["edits_per_cut"] for r in rows])


def _scored_rows(chosen: list, cache: Sequence, source: str | None = None) -> list[dict]:
    """The rows of ``chosen`` (per take of ``cache``: a choice and its row, or None) on
    the takes scored (not ``pool``) that had something to choose on, of ``source`` only
    when given."""
    return [found[1] for found, c in zip(chosen, cache, strict=True)
            if found is not None and not c.pool and source in (None, c.labelled.source)]


def _mean(values: list[float]) -> float:
    return float(np.mean(values)) if values else float("nan")
