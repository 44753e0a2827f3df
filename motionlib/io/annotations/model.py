"""The records, spans and tracks every annotation format reads and writes, and the checks
that hold for all of them."""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import PurePosixPath

from motionlib.errors import CaptureError, shorten

#: Format name -> what it is.
FORMATS = {"csv": "CSV (take, start, end, label)", "eaf": "ELAN (.eaf)",
           "labelstudio": "Label Studio JSON export"}
#: At most this many problems are listed in one error; the rest are counted.
MAX_PROBLEMS = 20


class AnnotationError(CaptureError):
    """An annotation file that cannot be used; ``problems`` lists each bad line or
    annotation ("line 4: end 12 is not after start 30")."""

    def __init__(self, message: str, *, problems: list[str] | None = None):
        self.problems = list(problems or [])
        super().__init__(message)


def fail(name: str, problems: list[str]):
    """Raise one :class:`AnnotationError` listing ``problems`` of file ``name``."""
    shown = problems[:MAX_PROBLEMS]
    more = len(problems) - len(shown)
    text = "; ".join(shown) + (f"; and {more} more" if more else "")
    raise AnnotationError(f"{name}: {text}", problems=problems)


@dataclass(frozen=True)
class Span:
    """Frames ``[start, stop)`` of a take with a label (None: a segment without one)."""

    start: int
    stop: int
    label: str | None
    where: str = ""
    #: ``(name, value)`` of the segment's attributes, in the project's order, for writing
    #: (the CSV writer gives each name an ``attribute:<name>`` column; reading ignores them).
    attributes: tuple[tuple[str, object], ...] = ()


@dataclass(frozen=True)
class Record(Span):
    """A span as a file holds it: which source (tier, annotation, annotator) and which
    take it names (empty: the file does not say)."""

    source: str = ""
    takes: tuple[str, ...] = ()


@dataclass
class Track:
    """One source's spans of one take, for writing. ``fps`` and ``n_frames`` are the take's."""

    take: str
    source: str
    fps: float
    n_frames: int
    spans: list[Span] = field(default_factory=list)


def sources_of(records: list[Record]) -> list[str]:
    """The distinct sources of ``records``, in file order."""
    return list(dict.fromkeys(r.source for r in records))


def _stem(name: str) -> str:
    """"13_30" for "13_30.bvh", "/data/upload/3/ab12-13_30.csv", "take.fbx#walk"."""
    base = PurePosixPath(name.replace("\\", "/").split("?")[0]).name
    base = base.replace("#", "_")
    return re.sub(r"\.[A-Za-z0-9]{1,5}$", "", base).strip().lower()


def matches_take(record: Record, take: str) -> bool:
    """Whether ``record`` is about the take named ``take`` (a record that names no take is
    about any). Names compare by file stem, ignoring case, folders and extension; a Label
    Studio upload's prefix (``ab12cd34-13_30.csv``) is ignored too."""
    if not record.takes:
        return True
    want = _stem(take)
    for name in record.takes:
        stem = _stem(name)
        if stem == want or re.sub(r"^[0-9a-f]{8}-", "", stem) == want:
            return True
    return False


def select(records: list[Record], *, take: str, source: str | None, name: str) -> list[Record]:
    """The records of one take and one source. ``source`` may be None when the file has
    only one; AnnotationError names the choices otherwise."""
    if not records:
        raise AnnotationError(f"{name}: the file holds no annotations")
    sources = sources_of(records)
    if source is None and len(sources) > 1:
        raise AnnotationError(f"source: {name} holds {len(sources)} sources "
                              f"({', '.join(map(repr, sources[:10]))}); choose one")
    if source is not None and source not in sources:
        raise AnnotationError(f"source: {name} has no source {shorten(source)}; it has "
                              f"{', '.join(map(repr, sources[:10]))}")
    chosen = [r for r in records if r.source == (source if source is not None else sources[0])]
    mine = [r for r in chosen if matches_take(r, take)]
    if not mine:
        named = sorted({t for r in chosen for t in r.takes})
        raise AnnotationError(f"take: no annotation of {name} is for take {shorten(take)}; "
                              f"the file names {', '.join(map(repr, named[:10]))}")
    return mine


def check_spans(spans: list[Span], *, n_frames: int, name: str) -> list[Span]:
    """``spans`` sorted by start, each inside ``[0, n_frames]`` with ``start < stop``, no
    two overlapping; AnnotationError lists every bad one by its ``where``."""
    problems = []
    for s in spans:
        if s.stop <= s.start:
            problems.append(f"{s.where}: end (frame {s.stop}) is not after start (frame {s.start})")
        elif s.start < 0 or s.stop > n_frames:
            problems.append(f"{s.where}: frames {s.start}..{s.stop} are outside the take "
                            f"(0..{n_frames}, end exclusive)")
    if problems:
        fail(name, problems)
    ordered = sorted(spans, key=lambda s: (s.start, s.stop))
    for before, after in zip(ordered, ordered[1:], strict=False):
        if after.start < before.stop:
            problems.append(f"{after.where} (frames {after.start}..{after.stop}) overlaps "
                            f"{before.where} (frames {before.start}..{before.stop}); a take's "
                            "segments do not overlap")
    if problems:
        fail(name, problems)
    return ordered
