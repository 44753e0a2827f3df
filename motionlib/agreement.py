"""Agreement between annotators who segmented and labelled the same take.

Three questions, three measures:

- Do they cut in the same places? Boundary F1 between two annotators' cuts within a
  tolerance (one-to-one optimal matching, see ``motionlib.metrics.match``). F1 is
  symmetric: ``2 * matched / (n_a + n_b)``.
- Do they give frames the same label? Cohen's kappa for a pair, Krippendorff's alpha
  (nominal) for any number; both correct raw agreement for agreement by chance.
- Where do they agree, label by label? The overlap (intersection over union) of the
  frames each annotator gave that label, averaged over pairs.

Labels are per frame: ``(n_annotators, n_frames)`` int codes with ``-1`` for a frame that
annotator left unlabelled. An unlabelled frame is *missing*, not a category: it is left out
of kappa (for that pair) and alpha (for that annotator), because an annotator who has not
labelled a segment yet has not disagreed with anybody.
"""

from __future__ import annotations

from itertools import combinations

import numpy as np

from motionlib.errors import InputError
from motionlib.metrics import boundary_scores

MISSING = -1


def boundary_agreement(cuts_a, cuts_b, *, fps: float, tolerance_s: float = 0.25) -> dict:
    """Precision, recall and F1 of annotator A's cuts against annotator B's.

    Parameters
    ----------
    cuts_a, cuts_b : (n,) cut frames (interior cuts; 0 and n_frames are not cuts).
    fps : frames per second of the take.
    tolerance_s : two cuts match when at most this many seconds apart.

    Returns
    -------
    dict with ``precision`` (share of A's cuts matched), ``recall`` (share of B's),
    ``f1`` and ``matched``. Two annotators who both made no cut agree fully (F1 = 1).
    """
    if fps <= 0:
        raise InputError(f"fps: must be positive, got {fps}")
    if tolerance_s < 0:
        raise InputError(f"tolerance_s: must be >= 0, got {tolerance_s}")
    # B's cuts play the truth: the same one-to-one matching and scores as a detector's.
    return boundary_scores(cuts_a, cuts_b, fps=fps, tolerance_s=tolerance_s)


def label_codes(segment_lists, n_frames: int) -> tuple[np.ndarray, list]:
    """Per-frame label codes of several annotators' segmentations of one take.

    Parameters
    ----------
    segment_lists : one list per annotator of ``(start, stop, label)``; frames are
        0-based, ``stop`` exclusive, ``label`` any hashable or None (unlabelled).
    n_frames : frames in the take.

    Returns
    -------
    codes : (n_annotators, n_frames) int, index into ``names``; -1 where unlabelled.
    names : the labels in order of first appearance.
    """
    codes = np.full((len(segment_lists), n_frames), MISSING, dtype=np.int64)
    names: list = []
    index: dict = {}
    for row, segments in enumerate(segment_lists):
        for start, stop, label in segments:
            if not 0 <= start <= stop <= n_frames:
                raise InputError(
                    f"segment [{start}, {stop}) of annotator {row} is outside the take's "
                    f"{n_frames} frames"
                )
            if label is None:
                continue
            if label not in index:
                index[label] = len(names)
                names.append(label)
            codes[row, start:stop] = index[label]
    return codes, names


def cohen_kappa(a, b) -> float:
    """Cohen's kappa of two annotators' per-frame labels.

    ``kappa = (p_o - p_e) / (1 - p_e)`` with ``p_o`` the share of frames labelled alike
    and ``p_e`` the share expected by chance from each annotator's label frequencies.
    Frames either annotator left unlabelled (-1) are skipped.

    Parameters
    ----------
    a, b : (n_frames,) int label codes, -1 for unlabelled.

    Returns
    -------
    kappa in [-1, 1]; 1.0 when both used one and the same label everywhere (no chance
    correction is possible, and they agree); NaN when no frame is labelled by both.
    """
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        raise InputError(f"label arrays differ in shape: {a.shape} and {b.shape}")
    both = (a != MISSING) & (b != MISSING)
    if not both.any():
        return float("nan")
    a, b = a[both], b[both]
    p_o = float(np.mean(a == b))
    size = int(max(a.max(), b.max())) + 1
    p_e = float(np.bincount(a, minlength=size) @ np.bincount(b, minlength=size)) / len(a) ** 2
    if p_e >= 1.0:
        return 1.0 if p_o == 1.0 else float("nan")
    return (p_o - p_e) / (1.0 - p_e)


def krippendorff_alpha(codes) -> float:
    """Krippendorff's alpha (nominal) over frames for any number of annotators.

    Parameters
    ----------
    codes : (n_annotators, n_frames) int label codes, -1 for unlabelled (missing).

    Returns
    -------
    alpha; 1.0 when every pairable frame carries the same single label; NaN when no
    frame is labelled by two annotators.
    """
    import krippendorff

    codes = np.asarray(codes)
    if codes.ndim != 2:
        raise InputError(f"codes: expected (n_annotators, n_frames), got shape {codes.shape}")
    pairable = (codes != MISSING).sum(axis=0) >= 2
    if not pairable.any():
        return float("nan")
    units = codes[:, pairable]
    if np.unique(units[units != MISSING]).size == 1:
        return 1.0  # one value only: no disagreement possible (the package would divide by 0)
    data = np.where(units == MISSING, np.nan, units.astype(float))
    return float(krippendorff.alpha(reliability_data=data, level_of_measurement="nominal"))


def label_overlap(codes, names) -> dict:
    """Per label: mean over annotator pairs of the intersection over union of its frames.

    Parameters
    ----------
    codes : (n_annotators, n_frames) int label codes, -1 for unlabelled.
    names : label of each code (as returned by ``label_codes``).

    Returns
    -------
    ``{label: {"overlap": IoU in [0, 1], "frames": frames given the label by anyone}}``;
    pairs where neither annotator used the label are left out of its mean.
    """
    codes = np.asarray(codes)
    out = {}
    for code, name in enumerate(names):
        has = codes == code
        ious = []
        for i, j in combinations(range(len(codes)), 2):
            union = np.count_nonzero(has[i] | has[j])
            if union:
                ious.append(np.count_nonzero(has[i] & has[j]) / union)
        out[name] = {
            "overlap": float(np.mean(ious)) if ious else float("nan"),
            "frames": int(np.count_nonzero(has.any(axis=0))),
        }
    return out


def segment_support(codes, row: int, start: int, stop: int) -> float:
    """Share of the other annotators' frames in ``[start, stop)`` that carry row's label there.

    The library's per-segment agreement: 1.0 when everyone else labelled those frames the
    same, 0.0 when nobody did. Returns NaN when there is no other annotator.

    Parameters
    ----------
    codes : (n_annotators, n_frames) int label codes; ``row`` is the segment's annotator.
    """
    codes = np.asarray(codes)
    others = np.delete(codes, row, axis=0)[:, start:stop]
    if others.shape[0] == 0 or stop <= start:
        return float("nan")
    mine = codes[row, start:stop]
    return float(np.mean(others == mine[None, :]))


def take_agreement(segment_lists, cut_lists, *, n_frames: int, fps: float,
                   tolerance_s: float = 0.25) -> dict:
    """Everything above for one take: pairwise boundaries and kappa, alpha, per-label overlap.

    Parameters
    ----------
    segment_lists : per annotator, ``(start, stop, label)`` segments (see ``label_codes``).
    cut_lists : per annotator, interior cut frames.
    n_frames, fps : the take's length and frame rate.

    Returns
    -------
    dict with ``pairs`` (``[{"a", "b", "boundary": {...}, "kappa"}]``, indices into the
    inputs), ``mean_boundary_f1``, ``alpha``, ``per_label`` and ``label_names``.
    """
    if len(segment_lists) != len(cut_lists):
        raise InputError("segment_lists and cut_lists must have one entry per annotator")
    codes, names = label_codes(segment_lists, n_frames)
    pairs = []
    for i, j in combinations(range(len(cut_lists)), 2):
        boundary = boundary_agreement(cut_lists[i], cut_lists[j], fps=fps, tolerance_s=tolerance_s)
        pairs.append({"a": i, "b": j, "boundary": boundary,
                      "kappa": cohen_kappa(codes[i], codes[j])})
    f1s = [p["boundary"]["f1"] for p in pairs]
    return {
        "pairs": pairs,
        "mean_boundary_f1": float(np.mean(f1s)) if f1s else float("nan"),
        "alpha": krippendorff_alpha(codes) if len(codes) >= 2 else float("nan"),
        "per_label": label_overlap(codes, names),
        "label_names": names,
    }
