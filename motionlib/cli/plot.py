"""Draw a segmentation: the method's signal(s) over time with the cuts as dashed lines.

matplotlib is an optional extra (``pip install "cutroom[plot]"``): only drawing needs it,
so it is imported here, when a plot is asked for, and its absence is a clear error.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from motionlib.errors import InputError
from motionlib.segmenters.base import Segmentation

MISSING = ('--plot: drawing needs matplotlib, which is not installed '
           '(pip install "cutroom[plot]")')


def require_matplotlib():
    """The ``matplotlib`` module; InputError saying how to install it when it is missing."""
    try:
        import matplotlib
    except ImportError:
        raise InputError(MISSING) from None
    return matplotlib


def plot_segmentation(
    result: Segmentation, *, fps: float, path: str | Path, title: str = ""
) -> Path:
    """Write a PNG of ``result.signals`` (time in seconds) with the cuts marked.

    Each signal is scaled to [0, 1] so several fit one axis; a cut's line is darker the
    higher its confidence.
    """
    matplotlib = require_matplotlib()
    matplotlib.use("Agg")
    from matplotlib import pyplot as plt

    fig, ax = plt.subplots(figsize=(12, 3.5), dpi=100)
    for name, signal in result.signals.items():
        y = np.asarray(signal, dtype=float)
        span = np.nanmax(y) - np.nanmin(y) if len(y) else 0.0
        scaled = (y - np.nanmin(y)) / span if span > 0 else np.zeros_like(y)
        ax.plot(np.arange(len(y)) / fps, scaled, linewidth=0.8, label=name)
    for cut, conf in zip(result.cuts, result.confidence, strict=True):
        ax.axvline(cut / fps, color="k", linestyle="--", linewidth=1, alpha=0.3 + 0.7 * conf)
    ax.set_xlabel("time (s)")
    ax.set_yticks([])
    ax.set_title(title)
    if result.signals:
        ax.legend(loc="upper right", fontsize="small")
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path)
    plt.close(fig)
    return path
