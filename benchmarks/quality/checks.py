"""The quality benchmark's checks of the default detector beyond the labelled takes as
recorded: where its placement could be (oracles that see the human cuts), short
activities (synthetic, and real ones cut short inside, throughout and at the ends of a
take), takes played slower and quicker, and long takes made of several.

Each check takes what the bench read (``read``: (labelled take, motion) pairs) or the data
folder, and returns the lines it prints after the tables.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from benchmarks.quality import tuning, variants
from benchmarks.quality.data import discover, unlabelled_motion
from benchmarks.quality.tables import mean_rows
from benchmarks.quality.tried import Tried, detector
from motionlib import adapt, metrics
from motionlib.errors import CaptureError
from motionlib.segmenters.default import PLACEMENTS, Default


def placement_bound_check(read: list) -> str:
    """How close placement could come with what each kind of take holds: for every cut of
    the shipped detector matched to a human cut (within 1 s), the error of the cut as
    placed; of the best of the detector's own five estimates (peak, split, turning point,
    pause, onset: step 5), picked by an oracle that sees the human cut; and of the
    turning point (local minimum of the 3 Hz pose speed, where step 5b cuts) nearest the
    human cut among those within 1 s of the placed cut, also picked by that oracle. Each
    the mean over takes of the median |cut - best estimate|, as in the placement summary;
    with how far apart the turning points lie (median gap). Where even the oracles stay
    far from the human cuts, the motion does not hold the moment the annotators cut at.
    ``read`` as in ``real_short_activity_check``."""
    per_kind: dict[str, list] = {}
    for t, take in read:
        errors = _placement_bound(t.truth, take)
        if errors is not None:
            per_kind.setdefault(t.kind, []).append(errors)
    if not per_kind:
        return "placement bound: no labelled take with a matched cut"
    lines = ["placement bound (mean over takes of the median |cut - best estimate|; the "
             "oracles see the human cut): as placed; best of the detector's five "
             "estimates; best turning point within 1 s of the placed cut; median gap "
             "between turning points:"]
    for group, kind in (("full-skeleton", "skeleton"), ("four-channel", "channels")):
        if kind in per_kind:
            placed, best, oracle, gap = np.nanmean(per_kind[kind], axis=0)
            n = len(per_kind[kind])
            lines.append(f"  {group:<14}({n} take{'s' if n > 1 else ''}) as placed "
                         f"{placed:.3f} s, best estimate {best:.3f} s, best turning point "
                         f"{oracle:.3f} s, turning points {gap:.2f} s apart")
    return "\n".join(lines)


def _placement_bound(truth: np.ndarray, take) -> list[float] | None:
    """One take's medians for ``placement_bound_check`` (s): as placed, best estimate,
    best turning point; and the median gap between turning points. None without a
    matched cut."""
    p = Default.validate_params({})
    a = Default.analyse(take, p)
    if a is None:
        return None
    found = Default.peaks(a, p)
    placed = Default.place(a, found, p)
    peaks = a.peak_frames(found.samples)
    estimates = np.stack([peaks, *(placed.stages[k] for k in PLACEMENTS)]) + a.first
    cuts = placed.cuts + a.first
    turns = placed.turns + a.first
    windows = metrics.as_windows(truth)
    ci, ti = metrics.match(cuts, windows, tolerance=int(round(take.fps)))
    if not len(ci):
        return None
    mids = windows[ti, 1]
    oracle = []
    for cut, mid in zip(cuts[ci], mids, strict=True):
        near = turns[np.abs(turns - cut) <= round(take.fps)]
        oracle.append(np.abs(near - mid).min() if len(near) else abs(cut - mid))
    errors = (np.abs(cuts[ci] - mids), np.abs(estimates[:, ci] - mids).min(axis=0), oracle)
    gap = float(np.median(np.diff(turns))) if len(turns) > 1 else float("nan")
    return [float(np.median(e)) / take.fps for e in errors] + [gap / take.fps]


SHORT_S = 2.5


def _detect(take, model, params: dict) -> np.ndarray:
    """The cuts of ``take``: adapted with ``model``, else zero-shot with ``params``, which
    may set the options of ``tried.Tried``."""
    if model is None:
        return detector(params)(**params).fit_predict(take).cuts
    return adapt.detect(take, model, **params).cuts


def short_activity_check(seeds: int = 6) -> str:
    """Recall of boundaries beside short activities on synthetic takes: zero-shot (the
    shipped settings), without its unmatched-poses step (``short_unmatched`` 0), with
    each ``short_activity`` option of ``tuning.TRIED``,
    and adapted (each take's model fitted on the other seeds' takes)."""
    from motionlib import synth

    takes = []
    for seed in range(seeds):
        take, segments = synth.generate(seed=seed, fps=60.0, duration=60.0,
                                        segment_seconds=(1.5, 6.0))
        cuts = np.asarray([s[0] for s in segments[1:]])
        lengths = np.asarray([s[1] - s[0] for s in segments]) / take.fps
        short = np.minimum(lengths[:-1], lengths[1:]) < SHORT_S
        takes.append((take, cuts, short))
    options = {f"short_activity={k:g}" + (f"/uniformity={u:g}" if u else ""):
               {"short_activity": k, "short_uniformity": u}
               for k in tuning.TRIED["short_activity"]
               for u in (0.0, *tuning.TRIED["short_uniformity"])}
    options = {"short_unmatched=0": {"short_unmatched": 0.0}, **options}
    found = {name: [0, 0] for name in ["zero-shot", *options, "adapted"]}
    for i, (take, cuts, short) in enumerate(takes):
        model = adapt.fit_cut_model([(t, c) for j, (t, c, _) in enumerate(takes) if j != i])
        runs = [("zero-shot", None, {}),
                *[(name, None, params) for name, params in options.items()],
                ("adapted", model, {})]
        for name, m, params in runs:
            detected = _detect(take, m, params)
            _, ti = metrics.match(detected, cuts, tolerance=int(take.fps))
            hit = np.zeros(len(cuts), dtype=bool)
            hit[ti] = True
            found[name][0] += int(hit[short].sum())
            found[name][1] += int(short.sum())
    parts = [f"{name} {k}/{n} ({k / max(n, 1):.2f})" for name, (k, n) in found.items()]
    return (f"short activities: synthetic takes ({seeds} seeds, 60 s at 60 fps, activities "
            f"1.5-6 s), boundaries beside an activity shorter than {SHORT_S:g} s found "
            f"within 1 s: " + ", ".join(parts) + " (adapted: fitted on the other seeds)")


SHORT_REAL_S = (1.8, 2.5)


def skeleton_takes(read: list) -> list:
    """The (labelled take, motion) pairs of full-skeleton takes."""
    return [(t, take) for t, take in read if t.kind == "skeleton"]


def real_short_activity_check(read: list, seconds=SHORT_REAL_S) -> str:
    """Short activities in real motion: each inner activity of each full-skeleton take cut
    down to ``seconds`` (``variants.shortened``), and whether the detector then finds both
    of its boundaries within 1 s, how many of them, and how many false cuts it makes.
    ``read``: (labelled take, its motion) pairs, as the bench read them.

    Rows: zero-shot; zero-shot without its unmatched-poses step (``short_unmatched`` 0,
    as before that step); the optional short-activity step as the default's docstring
    suggests it (``short_activity`` 4, ``short_uniformity`` 0.3); the shorter windows
    (2-4 s) the adaptation may choose; adapted, each take's model fitted on the other
    full-skeleton takes, as they are and with each of their activities shortened the same
    way (a studio whose reviewed takes hold such activities). Synthetic short activities
    (``short_activity_check``) are easier than these: their two activities differ by
    construction and they have no transitions. With a single full-skeleton take there is
    no adapted row.
    """
    read = skeleton_takes(read)
    if not read:
        return "short activities, real motion: no full-skeleton take"
    options = {"zero-shot": {}, "short_unmatched=0": {"short_unmatched": 0.0},
               "short_activity=4/uniformity=0.3":
               {"short_activity": 4.0, "short_uniformity": 0.3},
               "windows 2-4 s": {"scale_min_s": 2.0, "scale_max_s": 4.0}}
    cases = {duration: [(i, k, *cut) for i, (t, take) in enumerate(read)
                        for k in range(len(t.truth) - 1)
                        if (cut := variants.shortened(take, t.truth, k, duration))]
             for duration in seconds}
    adapted = ["adapted"] if len(read) > 1 else []  # one take: nothing to learn from
    found = {name: {d: [0, 0, 0] for d in seconds} for name in [*options, *adapted]}
    for duration, shortened in cases.items():
        models = []
        for i in range(len(read)):
            examples = [(take, t.truth[:, 1]) for j, (t, take) in enumerate(read) if j != i]
            examples += [(take, truth[:, 1]) for j, _, take, truth in shortened if j != i]
            models.append(adapt.fit_cut_model(examples) if examples else None)
        for i, k, take, truth in shortened:
            runs = [(name, None, params) for name, params in options.items()]
            runs += [("adapted", models[i], {})] if adapted else []
            for name, model, params in runs:
                cuts = _detect(take, model, params)
                ci, ti = metrics.match(cuts, truth, tolerance=int(round(take.fps)))
                hit = set(ti.tolist())
                row = found[name][duration]
                row[0] += k in hit and k + 1 in hit
                row[1] += (k in hit) + (k + 1 in hit)
                row[2] += len(cuts) - len(ci)
    head = "".join(f"{f'{d:g} s: both':>14}{'sides':>8}{'false':>7}" for d in seconds)
    lines = [f"short activities, real motion: each inner activity of the {len(read)} "
             f"full-skeleton takes cut down to {' / '.join(f'{d:g}' for d in seconds)} s by "
             f"removing its middle ({' / '.join(str(len(cases[d])) for d in seconds)} "
             f"cases); both of its boundaries found within 1 s, its boundaries found, false "
             f"cuts in the take (adapted: fitted on the other takes, as they are and "
             f"shortened):", f"  {'':<34}{head}"]
    for name, rows in found.items():
        cells = "".join(f"{f'{b}/{len(cases[d])}':>14}{f'{s}/{2 * len(cases[d])}':>8}{f:>7}"
                        for d, (b, s, f) in rows.items())
        lines.append(f"  {name:<34}{cells}")
    return "\n".join(lines)


THROUGHOUT_S = (2.5, 3.0, 4.0)


# Cuts and true cuts this close (s) to a join of two takes are not scored: what lies
# there (the end of one take, the start of the other) is neither take's activity.
JOIN_S = 2.0


def long_take_check(folder: Path) -> str:
    """Long takes made of several: the full-skeleton AMC takes of one skeleton (ASF), with
    labels and without, joined end to end two at a time in both orders and all together;
    each labelled part scored in its own span against its own cuts, beside the take on its
    own, both without what lies within ``JOIN_S`` of a join. The detector's kernel width
    and levels are the take's, so what else a take holds can change its cuts; this shows
    how much (a studio's takes are long and mixed, the labelled ones here 20-40 s)."""
    import motionlib

    labelled = [t for t in discover(folder, channels=False, bvh=False)[0]
                if t.asf is not None and t.path.suffix == ".amc"]
    groups: dict[Path, list] = {}
    for t in labelled:
        groups.setdefault(Path(t.asf).resolve(), []).append((t.name, t.path, t))
    for path, asf in unlabelled_motion(folder):
        if asf is not None and Path(asf).resolve() in groups:
            groups[Path(asf).resolve()].append((path.stem, path, None))
    lines, joined_rows, alone_rows = [], [], []
    for asf, members in groups.items():
        if len(members) < 2:
            continue
        try:
            parts = [(name, motionlib.read(path, asf=asf), t) for name, path, t in members]
        except CaptureError as exc:
            lines.append(f"  skipped {asf.name}: {exc}")
            continue
        joins = [[a, b] for a in parts for b in parts if a is not b and (a[2] or b[2])]
        if len(parts) > 2:
            joins.append(list(parts))
        alone = {name: Default().fit_predict(take).cuts for name, take, t in parts if t}
        for join in joins:
            for name, joined, own in _part_rows(join, alone):
                lines.append(f"  {' + '.join(n for n, _, _ in join):<26}{name:<8}"
                             f"{joined['f1@1s']:>7.3f}{joined['edits_per_cut']:>7.2f}"
                             f"{own['f1@1s']:>13.3f}{own['edits_per_cut']:>7.2f}")
                joined_rows.append(joined)
                alone_rows.append(own)
    if not joined_rows:
        return "long takes: no skeleton with two AMC takes, one of them labelled, here"
    mean = mean_rows({i: {"joined": j, "alone": a}
                      for i, (j, a) in enumerate(zip(joined_rows, alone_rows, strict=True))})
    return "\n".join([
        "long takes, real motion: the full-skeleton AMC takes of one skeleton joined end to "
        "end (two at a time in both orders, and all); each labelled part scored in its own "
        f"span, beside the take alone, both without cuts and true cuts within {JOIN_S:g} s "
        "of a join:",
        f"  {'joined':<26}{'part':<8}{'F1@1s':>7}{'edits':>7}{'alone: F1@1s':>13}{'edits':>7}",
        *lines,
        f"  mean over {len(joined_rows)} parts: joined F1@1s {mean['joined']['f1@1s']:.3f}, "
        f"edits {mean['joined']['edits_per_cut']:.2f}; alone {mean['alone']['f1@1s']:.3f}, "
        f"{mean['alone']['edits_per_cut']:.2f}"])


def _part_rows(parts, alone: dict) -> list[tuple[str, dict, dict]]:
    """The default detector on ``parts`` (name, take, labelled take or None) joined end to
    end. Per labelled part, ``metrics.evaluate`` of the joined take's cuts in its span and
    of its cuts alone (``alone[name]``), both against its own cuts and without what lies
    within ``JOIN_S`` of a join at its ends."""
    joined = variants.with_channels(
        parts[0][1], np.concatenate([take.channels for _, take, _ in parts]))
    cuts = Default().fit_predict(joined).cuts
    out, start = [], 0
    for i, (name, take, labelled) in enumerate(parts):
        n = take.n_frames
        if labelled is not None:
            gap = int(round(JOIN_S * take.fps))
            lo, hi = (gap if i else 0), (n - gap if i + 1 < len(parts) else n)
            truth = labelled.truth[(labelled.truth[:, 1] >= lo) & (labelled.truth[:, 1] < hi)]
            rows = []
            for found in (cuts - start, alone[name]):
                found = found[(found >= lo) & (found < hi)]
                rows.append(metrics.evaluate(found, truth, fps=take.fps))
            out.append((name, *rows))
        start += n
    return out


def short_takes_check(read: list, seconds=THROUGHOUT_S) -> str:
    """Takes made of short activities throughout: every inner activity of each
    full-skeleton take cut down to ``seconds`` (``variants.shortened_throughout``), and
    the mean F1@1 s and edits per true cut of the zero-shot detector and of the adapted
    one, fitted on the other takes cut down the same way (a studio whose reviewed takes
    are like that). ``read`` as in ``real_short_activity_check``; with a single
    full-skeleton take there is no adapted row.
    """
    read = skeleton_takes(read)
    if not read:
        return "short activities throughout a take: no full-skeleton take"
    rows = {"zero-shot": [], **({"adapted": []} if len(read) > 1 else {})}
    for duration in seconds:
        built = [variants.shortened_throughout(take, t.truth, duration) for t, take in read]
        scores = {name: [] for name in rows}
        for i, (take, truth) in enumerate(built):
            examples = [(other, cuts[:, 1]) for j, (other, cuts) in enumerate(built) if j != i]
            models = {"zero-shot": None, "adapted": adapt.fit_cut_model(examples)
                      if "adapted" in rows else None}
            for name in rows:
                cuts = adapt.detect(take, models[name]).cuts
                scores[name].append(metrics.evaluate(cuts, truth, fps=take.fps))
        for name in rows:
            rows[name].append([np.mean([r[key] for r in scores[name]])
                               for key in ("f1@1s", "edits_per_cut")])
    head = "".join(f"{f'{d:g} s: F1@1s':>16}{'edits':>7}" for d in seconds)
    lines = [f"short activities throughout a take, real motion: every inner activity of the "
             f"{len(read)} full-skeleton takes cut down to "
             f"{' / '.join(f'{d:g}' for d in seconds)} s by removing its middle; mean F1@1 s "
             f"and edits per true cut (adapted: fitted on the other takes cut down the same "
             f"way):", f"  {'':<12}{head}"]
    for name, cells in rows.items():
        lines.append(f"  {name:<12}" + "".join(f"{f1:>16.3f}{edits:>7.2f}"
                                               for f1, edits in cells))
    return "\n".join(lines)


TEMPO_SPEEDS = (0.8, 0.9, 1.0, 1.1, 1.25)


def tempo_check(read: list, speeds=TEMPO_SPEEDS) -> str:
    """Takes played slower and quicker (``variants.played_at``): each labelled take as if
    performed at ``speeds`` times its pace, its true cuts moved with it, scored as
    shipped and with the ``tempo`` setting (time settings scaled by the take's own
    movement cycle). A studio's performers do not all move at the pace of the takes the
    settings were chosen on; this shows how much that costs."""
    if not read:
        return "tempo: no labelled take"
    settings = (("shipped", {}), ("tempo", {"tempo": True}))
    per_take: dict[tuple, dict] = {}  # (kind, name) -> (setting, speed) -> row
    for t, take in read:
        rows = per_take.setdefault((t.kind, t.name), {})
        for speed in speeds:
            played, truth = (take, t.truth) if speed == 1.0 else \
                variants.played_at(take, t.truth, speed)
            for setting, params in settings:
                cuts = Tried(**params).fit_predict(played).cuts
                rows[(setting, speed)] = metrics.evaluate(cuts, truth, fps=take.fps)
    head = "".join(f"{f'x{s:g}: F1@1s':>14}{'edits':>7}{'err s':>7}" for s in speeds)
    lines = [f"tempo: each labelled take played at {' / '.join(f'{s:g}' for s in speeds)} "
             f"times its pace (its cuts moved with it); mean F1@1 s, edits per true cut and "
             f"median placement error, as shipped and with tempo on:",
             f"  {'':<28}{head}"]
    for group, kind in (("full-skeleton", "skeleton"), ("four-channel", "channels")):
        mean = mean_rows({key: rows for key, rows in per_take.items() if key[0] == kind})
        if not mean:
            continue
        for setting, _ in settings:
            cells = "".join(f"{m['f1@1s']:>14.3f}{m['edits_per_cut']:>7.2f}"
                            f"{m['median_error_s']:>7.2f}"
                            for m in (mean[(setting, speed)] for speed in speeds))
            lines.append(f"  {group + ', ' + setting:<28}{cells}")
    return "\n".join(lines)


EDGE_REAL_S = (1.5, 1.8, 2.5)


def edge_activity_check(read: list, seconds=EDGE_REAL_S) -> str:
    """Short activities at the ends of real takes: the first and the last activity of each
    full-skeleton take cut down to ``seconds`` (``variants.trimmed``), and whether the
    zero-shot detector then finds its boundary within 1 s, and how many false cuts it
    makes. The novelty windows there see the take mirrored at its end. ``read`` as in
    ``real_short_activity_check``; a take without a cut has no such boundary and is left
    out.
    """
    read = [(t, take) for t, take in skeleton_takes(read) if len(t.truth)]
    if not read:
        return "short activities at the ends of a take: no full-skeleton take with a cut"
    cells = []
    for duration in seconds:
        found = cases = false = 0
        for t, take in read:
            for side, index in (("first", 0), ("last", -1)):
                cut = variants.trimmed(take, t.truth, side, duration)
                if cut is None:
                    continue
                short, truth = cut
                cuts = adapt.detect(short).cuts
                ci, _ = metrics.match(cuts, truth, tolerance=int(round(short.fps)))
                cases += 1
                found += bool(len(cuts)) and \
                    np.abs(cuts - truth[index, 1]).min() <= round(short.fps)
                false += len(cuts) - len(ci)
        cells.append(f"{duration:g} s {found}/{cases} (false cuts {false})")
    return (f"short activities at the ends of a take, real motion: the first and the last "
            f"activity of each of the {len(read)} full-skeleton takes cut down by dropping "
            f"the take's first or last frames; its boundary found within 1 s, zero-shot: "
            + ", ".join(cells))


