"""Gaps in point takes: where a marker was not seen, a frame holds NaN.

Stored and exported data keep the gaps; only the features a segmenter computes need a
value in every frame, and :func:`filled` gives them one.
"""

import numpy as np


def filled(points: np.ndarray) -> np.ndarray:
    """Gaps closed for computing features: each coordinate linearly interpolated in time
    between the frames where it was seen, held at its first / last seen value beyond them.

    Features (distances, angles, kernels) need a value in every frame; a straight line
    across a gap is the least a feature can assume there. Never used on stored data.

    Parameters
    ----------
    points : (n_frames, n_points, 3), NaN at gaps.

    Returns
    -------
    (n_frames, n_points, 3) float64; a point never seen stays NaN.
    """
    out = np.array(points, dtype=np.float64)
    flat = out.reshape(len(out), -1)
    missing = np.isnan(flat)
    frames = np.arange(len(out))
    for column in np.flatnonzero(missing.any(axis=0)):
        seen = ~missing[:, column]
        if seen.any():
            flat[:, column] = np.interp(frames, frames[seen], flat[seen, column])
    return out
