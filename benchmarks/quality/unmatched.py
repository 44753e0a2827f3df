"""The quality benchmark's checks of the default's unmatched-poses step (step 4c of
``motionlib.segmenters.default``): how its settings are chosen leave-one-take-out on real
takes with activities cut short, and where it fires on the takes without labels."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from benchmarks.quality import tuning, variants
from benchmarks.quality.checks import skeleton_takes
from benchmarks.quality.data import unlabelled_motion
from motionlib import metrics
from motionlib.errors import CaptureError
from motionlib.segmenters.default import Default

# How step 4c's settings (``short_unmatched`` and the half-width of its two cuts) are
# chosen: the options, and the cut-down takes they are chosen and scored on.
UNMATCHED_LEVELS = (0.0, 0.5, 1.0, 1.5, 2.0, 3.0)
UNMATCHED_HALVES = (0.75, 1.0, 1.25)
UNMATCHED_INNER_S = (1.5, 1.8, 2.2, 2.5, 3.0)
UNMATCHED_THROUGHOUT_S = (2.5, 3.0, 4.0, 5.0)


class ShippedWindows(Default):
    """The default detector whose windows' peaks are those of the shipped settings
    (the support test spares the short activities the shipped step finds) whatever
    ``short_unmatched`` is: only the unmatched-poses step itself varies."""

    @classmethod
    def window_peaks(cls, analysis, p: dict) -> tuple[np.ndarray, np.ndarray]:
        shipped = Default.params["short_unmatched"].default
        return super().window_peaks(analysis, {**p, "short_unmatched": shipped})


def half_width(half_s: float) -> type[Default]:
    """``ShippedWindows`` with the unmatched-poses step's two cuts ``half_s`` either side
    of its stretch's middle."""
    return type(f"HalfWidth{half_s:g}", (ShippedWindows,), {"unmatched_half_s": half_s})


class Unguarded(Default):
    """The default detector without the unmatched-poses step's take-median guard."""

    unmatched_relative = 0.0


def unmatched_choice_check(read: list) -> str:
    """How the unmatched-poses step's settings (``segmenters.default`` step 4c) are
    chosen, and how that choice scores on takes it was not chosen on.

    Material: every take as it is (full-skeleton and four-channel), and each
    full-skeleton take with each inner activity cut down to ``UNMATCHED_INNER_S``
    (``variants.shortened``, one at a time) and with all of them cut down to
    ``UNMATCHED_THROUGHOUT_S`` (``variants.shortened_throughout``). A setting's score
    on some material is the mean over the three families (as they are, one cut down,
    all cut down) of the mean F1@1 s; the first of equal settings (off first) wins.
    Each full-skeleton capture is left out in turn (its four-channel view with it): the
    setting is chosen on everything else, and scored on the left-out take's material,
    beside the step off. ``read``: (labelled take, motion) pairs, as the bench read them.
    """
    skeletons = skeleton_takes(read)
    if not skeletons:
        return "unmatched-poses step: no full-skeleton take to choose its settings on"
    material = [(t.name, "as is", take, t.truth, None) for t, take in read if len(t.truth)]
    for t, take in skeletons:
        for k in range(len(t.truth) - 1):
            for seconds in UNMATCHED_INNER_S:
                cut = variants.shortened(take, t.truth, k, seconds)
                if cut is not None:
                    material.append((t.name, "one cut down", *cut, k))
        for seconds in UNMATCHED_THROUGHOUT_S:
            material.append((t.name, "all cut down",
                             *variants.shortened_throughout(take, t.truth, seconds), None))
    settings = [(0.0, Default.unmatched_half_s)] + [
        (level, half) for level in UNMATCHED_LEVELS if level > 0 for half in UNMATCHED_HALVES]
    variants_of = {half: half_width(half) for half in {*UNMATCHED_HALVES, settings[0][1]}}
    p = Default.validate_params({})
    ratios: list[float] = []  # each firing's level / take median, without the guard
    scores = {}  # (setting, material index) -> (F1@1 s, both sides of the short one found)
    for i, (_, _, take, truth, k) in enumerate(material):
        analysis = Default.analyse(take, p)
        if analysis is None:
            continue
        ratios += unmatched_ratios(analysis, p)
        for level, half in settings:
            method = variants_of[half]
            found = method.peaks(analysis, {**p, "short_unmatched": level})
            cuts = Default.place(analysis, found, p).cuts + analysis.first
            _, ti = metrics.match(cuts, truth, tolerance=int(round(take.fps)))
            scores[(level, half), i] = (
                metrics.evaluate(cuts, truth, fps=take.fps)["f1@1s"],
                k is not None and k in ti and k + 1 in ti)

    def score(setting, used) -> float:
        families: dict[str, list[float]] = {}
        for i in used:
            if (setting, i) in scores:
                families.setdefault(material[i][1], []).append(scores[setting, i][0])
        return round(float(np.mean([np.mean(v) for v in families.values()])), 9) \
            if families else -math.inf

    def family(setting, used, name) -> tuple[float, int, int]:
        rows = [scores[setting, i] for i in used
                if material[i][1] == name and (setting, i) in scores]
        return (float(np.mean([r[0] for r in rows])) if rows else math.nan,
                sum(r[1] for r in rows), len(rows))

    def label(setting) -> str:
        return "off" if setting[0] == 0 else f"{setting[0]:g} / {setting[1]:g} s"

    everything = range(len(material))
    lines = [f"unmatched-poses step (short_unmatched / half-width of its two cuts), chosen "
             f"leave-one-take-out: each full-skeleton take left out, the setting chosen on "
             f"the other takes as they are, with one inner activity cut down to "
             f"{' / '.join(f'{s:g}' for s in UNMATCHED_INNER_S)} s and with all cut down to "
             f"{' / '.join(f'{s:g}' for s in UNMATCHED_THROUGHOUT_S)} s (mean of the three "
             f"families' mean F1@1 s), and scored on the take left out:",
             f"  {'left out':<10}{'chosen':>14}  {'as is F1':>9}{'one cut down: F1':>18}"
             f"{'both':>8}{'all cut down F1':>17}"]
    totals = {"chosen": [], "off": []}
    for t, _ in skeletons:
        used = [i for i in everything if material[i][0] != t.name]
        held = [i for i in everything if material[i][0] == t.name]
        best = max(settings, key=lambda s: score(s, used))
        for name, setting in (("chosen", best), ("off", settings[0])):
            cells = (family(setting, held, "as is")[0], *family(setting, held, "one cut down"),
                     family(setting, held, "all cut down")[0])
            totals[name].append(cells)
            if name == "chosen" or setting != best:
                lines.append(_unmatched_row(t.name if name == "chosen" else "",
                                            label(setting), cells))
    for name, rows in totals.items():
        lines.append(_unmatched_row("all" if name == "chosen" else "", name, (
            float(np.mean([r[0] for r in rows])), float(np.mean([r[1] for r in rows])),
            sum(r[2] for r in rows), sum(r[3] for r in rows),
            float(np.mean([r[4] for r in rows])))))
    best = max(settings, key=lambda s: score(s, everything))
    lines.append(f"  chosen on all: {label(best)}; shipped: short_unmatched "
                 f"{Default.params['short_unmatched'].default:g}, half-width "
                 f"{Default.unmatched_half_s:g} s")
    lines.append(f"  {_guard_line(ratios)}")
    return "\n".join(lines)


def unmatched_ratios(analysis, p: dict) -> list[float]:
    """For each kept peak the unmatched-poses step (at the settings ``p``) replaces
    without its take-median guard, the level of the stretch it fires on over the take's
    median (``Peaks.unmatched`` of ``Unguarded``), in peak order."""
    found = Unguarded.peaks(analysis, p)
    return [found.unmatched[peak] for peak in sorted(found.unmatched)]


def _guard_line(ratios: list[float]) -> str:
    relative = Default.unmatched_relative
    if not ratios:
        return "take-median guard: the step fires nowhere on this material"
    kept = sum(r >= relative for r in ratios)
    return (f"take-median guard (stretch at least {relative:g} x the take's median "
            f"as well): of the {len(ratios)} firings on this material without it, {kept} "
            f"kept; level / take median from {min(ratios):.1f} (median "
            f"{float(np.median(ratios)):.1f})")


def unmatched_guard_check(folder: Path) -> str:
    """The unmatched-poses step on the full-skeleton takes without segment labels
    (``unlabelled_motion``): the default detector's number of cuts as shipped
    and with the step off, and, for each stretch the step would fire on without its
    take-median guard, its level over the take's median (the guard keeps it from
    ``Default.unmatched_relative`` on). Nothing is scored (there are no labels): a take that does
    not repeat itself (boxing, dance) is where the guard acts, and these show where it
    does."""
    import motionlib

    takes = unlabelled_motion(folder)
    if not takes:
        return "unmatched-poses step on takes without labels: none under the data folder"
    p = Default.validate_params({})
    rows = []
    for path, asf in takes:
        try:
            take = motionlib.read(path, asf=asf)
        except CaptureError as exc:
            rows.append(f"  {path.stem:<10} skipped: {exc}")
            continue
        cache = tuning.TakeCache(None, take)  # one analysis for the three questions
        counts = [len(cache.cuts(params)) for params in ({}, {"short_unmatched": 0.0})]
        analysis = cache.analysis(p)
        ratios = [] if analysis is None else unmatched_ratios(analysis, p)
        firings = ", ".join(f"{r:.1f}x ({'kept' if r >= Default.unmatched_relative else 'not'})"
                            for r in ratios)
        rows.append(f"  {path.stem:<10}{take.n_frames / take.fps:>7.1f}{counts[0]:>9}"
                    f"{counts[1]:>10}   {firings or '-'}")
    return "\n".join([
        f"unmatched-poses step on the full-skeleton takes without segment labels (not "
        f"scored): cuts as shipped and with the step off; each stretch the step fires on "
        f"without its take-median guard, its level / the take's median, kept from "
        f"{Default.unmatched_relative:g}x:",
        f"  {'take':<10}{'s':>7}{'shipped':>9}{'step off':>10}   firings", *rows])


def _unmatched_row(name: str, setting: str, cells: tuple) -> str:
    as_is, f1, both, n, all_cut = cells
    return (f"  {name:<10}{setting:>14}  {as_is:>9.3f}{f1:>18.3f}{f'{both}/{n}':>8}"
            f"{all_cut:>17.3f}")


