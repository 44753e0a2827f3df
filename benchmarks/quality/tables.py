"""The quality benchmark's text tables: one per take, the means, the placement summary and
the tables of how the default's settings were chosen (``tuning``)."""

from __future__ import annotations

import math

from benchmarks.quality import tuning

COLUMNS = (
    ("P@.5s", "precision@0.5s"), ("R@.5s", "recall@0.5s"), ("F1@.5s", "f1@0.5s"),
    ("P@1s", "precision@1s"), ("R@1s", "recall@1s"), ("F1@1s", "f1@1s"),
    ("edits/cut", "edits_per_cut"), ("med err s", "median_error_s"), ("in window", "in_window"),
    ("time s", "time_s"), ("cuts", "n_cuts"),
)


def mean_rows(results: dict[str, dict]) -> dict[str, dict]:
    """Per method present on every take, the mean of each column (NaN errors skipped)."""
    if not results:
        return {}
    names = [n for n in next(iter(results.values())) if all(n in r for r in results.values())]
    out = {}
    for name in names:
        per_take = [results[t][name] for t in results]
        out[name] = {
            key: _nanmean([row[key] for row in per_take]) for key in per_take[0]
        }
    return out


def _nanmean(values: list[float]) -> float:
    finite = [v for v in values if not math.isnan(v)]
    return sum(finite) / len(finite) if finite else float("nan")


def format_table(title: str, rows: dict[str, dict]) -> str:
    """A fixed-width text table, one row per method."""
    width = max([len(name) for name in rows] + [6])
    head = f"{'method':<{width}} " + " ".join(f"{label:>9}" for label, _ in COLUMNS)
    lines = [title, head, "-" * len(head)]
    for name, row in rows.items():
        cells = []
        for _, key in COLUMNS:
            value = row[key]
            cells.append(f"{value:>9.1f}" if key == "n_cuts" else f"{value:>9.3f}")
        lines.append(f"{name:<{width}} " + " ".join(cells))
    return "\n".join(lines)


def placement_summary(results: dict[str, dict], groups: list[tuple[str, list[str]]],
                      names=("default", "default/loo")) -> str:
    """Placement of the default rows by kind of take: the mean over takes of the median
    |cut - best estimate| (s), and of the share of matched cuts inside the annotators'
    transition window on takes whose labels give one ("in window")."""
    lines = ["placement by kind of take (mean over takes; 'in window': share of matched cuts "
             "inside the labelled transition window, takes with windows only):"]
    for name in names:
        parts = []
        for group, takes in groups:
            rows = [results[t][name] for t in takes if name in results[t]]
            if not rows:
                continue
            error = _nanmean([r["median_error_s"] for r in rows])
            inside = [r["in_window"] for r in rows if not math.isnan(r["in_window"])]
            share = (f", in window {_nanmean(inside):.2f} ({len(inside)} "
                     f"take{'s' if len(inside) > 1 else ''})") if inside else ""
            parts.append(f"{group} {error:.3f} s{share}")
        if parts:
            lines.append(f"  {name:<12} " + "; ".join(parts))
    return "\n".join(lines)


def out_of_sample_table(tried: tuning.Selection) -> str:
    """The default's settings: what was chosen on all takes, and how each option of each
    setting scores leave-one-take-out (the others still chosen without the take), first
    in the shipped grid, then for the options tried and not shipped (``tuning.TRIED``,
    chosen with all of ``tuning.tried_grid()``)."""
    selection = tried.shipped()
    chosen = selection.chosen()
    pooled = sum(c.pool for c in selection.cache)
    lines = [f"default settings chosen on all {len(selection.cache)} takes"
             + (f" ({pooled} of them from the pool)" if pooled else "") + " from tuning.GRID: "
             + ", ".join(f"{k}={v:g}" if not isinstance(v, bool) else f"{k}={v}"
                         for k, v in chosen.items()),
             "out of sample (leave-one-take-out) with one setting imposed:",
             f"  {'setting':<15}{'value':>12}{'F1@1s':>9}{'edits/cut':>11}"]
    for key, value, f1, edits in tuning.out_of_sample(selection):
        lines.append(f"  {key:<15}{str(value):>12}{f1:>9.3f}{edits:>11.3f}")
    lines.append("  tried, not shipped (the other settings chosen from the grid with them):")
    grid = tuning.tried_grid()
    for key, value, f1, edits in tuning.out_of_sample(tried, {k: grid[k] for k in tuning.TRIED}):
        lines.append(f"  {key:<15}{str(value):>12}{f1:>9.3f}{edits:>11.3f}")
    lines.append("  how the choice is made (every setting chosen the same way):")
    for name, f1, edits in tuning.objectives(selection):
        shipped = " (shipped)" if name == "F1@1s first" else ""
        lines.append(f"  {'objective':<15}{name:>12}{f1:>9.3f}{edits:>11.3f}{shipped}")
    return "\n".join(lines + ["", source_table(selection)])


def source_table(selection: tuning.Selection) -> str:
    """The default's settings chosen on the other label sources only, scored on each
    source, beside leave-one-take-out (which chooses on the same source's other takes
    too)."""
    rows = tuning.by_source(selection)
    lines = ["settings chosen on the other label sources only (leave-one-source-out) and "
             "leave-one-take-out, mean over each source's takes:",
             f"  {'source':<12}{'takes':>6}{'other sources: F1@1s':>22}{'edits':>7}"
             f"{'med err':>8}{'loo: F1@1s':>12}{'edits':>7}{'med err':>8}"]
    for source, n, other, loo in rows:
        lines.append(f"  {source:<12}{n:>6}{other['f1@1s']:>22.3f}{other['edits_per_cut']:>7.3f}"
                     f"{other['median_error_s']:>8.3f}{loo['f1@1s']:>12.3f}"
                     f"{loo['edits_per_cut']:>7.3f}{loo['median_error_s']:>8.3f}")
    return "\n".join(lines)


