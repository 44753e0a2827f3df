"""Synthetic example takes for the adaptation tests: a take with its true cuts, and keyed
examples that record each time their take is read."""

import numpy as np

from motionlib import synth
from motionlib.adapt import Example

FPS = 60.0


def take_with_cuts(seed, **kw):
    """(take, cuts): a seeded synthetic take at FPS and the frames where its activities
    change (``synth.generate``'s keywords; 50 s by default)."""
    take, segments = synth.generate(seed=seed, fps=FPS, duration=kw.pop("duration", 50.0), **kw)
    return take, np.asarray([start for start, _, _ in segments[1:]], dtype=np.int64)


def keyed_examples(seeds, reads, **kw):
    """Keyed examples of ``take_with_cuts`` that append their seed to ``reads`` each time
    their take is read."""
    out = []
    for seed in seeds:
        take, cuts = take_with_cuts(seed, **kw)

        def read(take=take, seed=seed):
            reads.append(seed)
            return take
        out.append(Example(name=f"take {seed}", cuts=cuts, fps=take.fps,
                           n_frames=take.n_frames, read=read, key=f"take-{seed}"))
    return out
