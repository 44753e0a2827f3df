"""What is kept of an example take: its *study*, the candidates a model chooses among.

A take's candidates depend on the take and the detector settings only, never on its
cuts, so a study made once serves every later fit and refit: ``fit_cut_model`` reads it
from a :class:`Studies` store when kept there, and analyses the take (and keeps the
study) otherwise. The service keeps studies beside the take's cached parse; a benchmark
keeps them in memory.
"""

from __future__ import annotations

import hashlib
import json
from typing import Protocol

import numpy as np

from motionlib.adapt._candidates import study_take
from motionlib.adapt._examples import Example, ExampleError

# Bump when what a study holds, or how the detector computes it, changes: every stored
# study then misses once and is made again.
STUDY_VERSION = 1
# The arrays every study holds (``_candidates.candidates_of``); a study may hold more.
STUDY_ARRAYS = frozenset({"features", "zero_shot", "stages", "fps", "n_frames"})


class Studies(Protocol):
    """Where ``fit_cut_model`` keeps what it learnt from each example (its *study*).

    A study is a dict of numpy arrays; ``study_key`` names the detector settings it was
    made with, and a store returns a study only for the same ``study_key`` (a store may
    keep one study per ``example_key``).
    """

    def load(self, example_key: str, study_key: str) -> dict[str, np.ndarray] | None: ...

    def save(self, example_key: str, study_key: str, arrays: dict[str, np.ndarray]) -> None: ...


class MemoryStudies:
    """``Studies`` in a dict: one study per example, for as long as the object lives."""

    def __init__(self):
        self.items: dict[str, tuple[str, dict[str, np.ndarray]]] = {}

    def load(self, example_key, study_key):
        stored = self.items.get(example_key)
        return stored[1] if stored is not None and stored[0] == study_key else None

    def save(self, example_key, study_key, arrays):
        self.items[example_key] = (study_key, arrays)


def study_key(p: dict) -> str:
    """What a take's study depends on besides the take: the detector settings."""
    text = json.dumps([STUDY_VERSION, sorted(p.items())])
    return hashlib.sha256(text.encode()).hexdigest()


def kept_study(example: Example, p: dict, studies: Studies | None) -> dict:
    """The study of ``example`` under the validated default settings ``p``: from
    ``studies`` when kept there (an example with a ``key`` only), else computed from the
    take (and kept). ExampleError for a take too short to analyse."""
    keep = studies is not None and example.key is not None
    key = study_key(p) if keep else ""
    if keep:
        stored = studies.load(example.key, key)
        if stored is not None and STUDY_ARRAYS <= set(stored):
            return stored
    arrays = study_take(example.read(), p)
    if arrays is None:
        raise ExampleError(f"{example.name}: too short to learn from "
                           f"({example.n_frames} frames)")
    if keep:
        studies.save(example.key, key, arrays)
    return arrays
