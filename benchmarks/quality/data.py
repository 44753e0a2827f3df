"""The labelled real CMU takes the quality benchmark scores (and the detector's tests read).

Every labelled take in the shared data layout (``motionlib.shared_data.data_dir()``; see
its README) is found, whatever its name:

- ``labels/mocap6/segments/<take>.csv`` (runs of 10 fps blocks, AMC frames 1-based) and
  ``labels/cmu86_kruger2017/<take>.csv`` (Krüger et al. 2017 transition windows);
- ``labels/cmu86_baak/intervals.csv`` (Baak / Müller's sparse intervals of the same
  subject-86 takes, another convention: ``baak_takes``, not among ``discover``'s takes);
- their motion: ``cmu/bvh/<take>.bvh`` where present (label frames shifted by the BVH's
  extra T-pose lines), else ``cmu/amc/<take>.amc`` with ``cmu/asf/<subject>.asf``, else
  ``cmu/channels4d/<take>.4d.txt`` (four AMC channels per frame: a *four-channel take*,
  :class:`ChannelTake`, for whatever does not need the full skeleton).

Every loader returns true cuts as ``(n, 3)`` windows ``(lo, mid, hi)`` of 0-based *take*
frames (``motionlib.metrics``).
"""

from __future__ import annotations

import csv
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from benchmarks.harness import data_dir
from motionlib.errors import MotionlibError


class LabelError(MotionlibError):
    """A label file is malformed; the message names the file, line and value."""


@dataclass(eq=False)
class ChannelTake:
    """A take known only by a few channels per frame (no skeleton).

    channels : (n_frames, n_channels) float, here the AMC angles in degrees.
    """

    name: str
    fps: float
    channels: np.ndarray
    path: str | None = None
    rest_pose_frame: None = None

    @property
    def n_frames(self) -> int:
        return int(self.channels.shape[0])


# The CMU capture rate: AMC and its four-channel extracts store no rate.
CMU_FPS = 120.0


def read_channels(path: Path) -> ChannelTake:
    """A ``cmu/channels4d/<take>.4d.txt`` file: one row of numbers per AMC frame."""
    path = Path(path)
    rows = []
    with open(path, encoding="utf-8") as fh:
        for line, text in enumerate(fh, start=1):
            try:
                rows.append([float(v) for v in text.split()])
            except ValueError:
                raise LabelError(f"{path}: line {line}: not numbers: {text.strip()[:40]!r}") \
                    from None
            if len(rows[-1]) != len(rows[0]) or not np.isfinite(rows[-1]).all():
                raise LabelError(f"{path}: line {line}: expected {len(rows[0])} finite "
                                 f"numbers, got {text.strip()[:40]!r}")
    if not rows:
        raise LabelError(f"{path}: no frames")
    return ChannelTake(name=path.name.split(".")[0], fps=CMU_FPS,
                       channels=np.asarray(rows, dtype=float), path=str(path))


@dataclass(frozen=True)
class LabelledTake:
    """One capture with human cuts: ``truth`` is ``(n, 3)`` windows in take frames.

    ``kind`` is ``"skeleton"`` (a BVH, or an AMC with ``asf``) or ``"channels"`` (a
    four-channel take, read as a :class:`ChannelTake`); ``source`` names the label set.
    """

    name: str
    path: Path
    asf: Path | None
    truth: np.ndarray
    source: str
    kind: str = "skeleton"
    labels: Path | None = None  # the label file, named when it does not fit the motion

    def read(self):
        """The motion; LabelError when a labelled cut lies outside it (labels made for
        another take, or at another frame rate, would otherwise score as misses)."""
        if self.kind == "channels":
            take = read_channels(self.path)
        else:
            import motionlib

            take = motionlib.read(self.path, asf=self.asf)
        outside = [int(f) for f in self.truth[:, 1] if not 0 <= f < take.n_frames]
        if outside:
            raise LabelError(f"{self.labels or self.name}: cut at frame {outside[0]} is "
                             f"outside {self.path} ({take.n_frames} frames): the labels "
                             f"do not fit this motion")
        return take


def _rows(path: Path, columns: tuple[str, ...]) -> list[tuple[int, dict[str, str]]]:
    """CSV rows with their line numbers; LabelError if a column is missing or the file
    cannot be read as UTF-8 text."""
    try:
        with open(path, newline="", encoding="utf-8") as fh:
            reader = csv.DictReader(fh)
            missing = [c for c in columns if c not in (reader.fieldnames or [])]
            if missing:
                raise LabelError(f"{path}: line 1: missing column {missing[0]!r}")
            return [(reader.line_num, row) for row in reader]
    except (OSError, UnicodeDecodeError, csv.Error) as exc:
        raise LabelError(f"{path}: cannot read the labels: {exc}") from None


def _int(path: Path, line: int, row: dict[str, str], column: str) -> int:
    value = row.get(column)
    try:
        return int(value)
    except (TypeError, ValueError):
        raise LabelError(f"{path}: line {line}: {column} is not an integer: {value!r}") from None


def mocap6_truth(path: Path, *, frame_offset: int = 0) -> np.ndarray:
    """True cuts from a mocap6 ``segments/<seq>.csv``.

    Each segment after the first starts a new activity at AMC frame ``start_frame``
    (1-based), i.e. 0-based AMC frame ``start_frame - 1``; ``frame_offset`` converts to
    another take's frames (+1 for the cgspeed BVH, whose line 0 is an added T-pose).
    """
    path = Path(path)
    starts = [_int(path, n, r, "start_frame") for n, r in _rows(path, ("start_frame",))]
    if not starts:
        raise LabelError(f"{path}: no segments")
    if starts != sorted(starts):
        raise LabelError(f"{path}: start_frame values are not increasing: {starts}")
    cuts = np.asarray(starts[1:], dtype=np.int64) - 1 + frame_offset
    return np.repeat(cuts[:, None], 3, axis=1)


MOCAP6_BLOCK = 12  # AMC frames per label of a mocap6 block file (10 fps blocks of 120 fps)


def mocap6_block_truth(path: Path) -> np.ndarray:
    """True cuts from an original mocap6 ``<seq>.txt``: one activity id per 12-frame block
    of the AMC (block i covers 1-based AMC frames 12(i-1)+1 .. 12i), so a new activity
    that starts in block i (1-based) starts at 0-based AMC frame 12(i-1). The same cuts as
    ``segments/<seq>.csv``, which lists those blocks as runs.
    """
    path = Path(path)
    try:
        words = path.read_text(encoding="utf-8").split()
    except (OSError, UnicodeDecodeError) as exc:
        raise LabelError(f"{path}: cannot read the labels: {exc}") from None
    labels = []
    for block, word in enumerate(words, start=1):
        try:
            labels.append(int(word))
        except ValueError:
            raise LabelError(f"{path}: block {block}: activity id is not an integer: "
                             f"{word!r}") from None
    if not labels:
        raise LabelError(f"{path}: no blocks")
    starts = np.flatnonzero(np.diff(labels)) + 1  # 0-based blocks where a new run starts
    cuts = MOCAP6_BLOCK * starts.astype(np.int64)
    return np.repeat(cuts[:, None], 3, axis=1)


def kruger_truth(path: Path) -> np.ndarray:
    """True cuts from a subject-86 ``cmu86_kruger2017/86_XX.csv``.

    Segment k ends somewhere in AMC frames ``[end_lo, end_hi]`` (1-based, inclusive),
    best estimate ``end_mid``; the next segment starts one frame later, which is 0-based
    frame ``end`` itself. The last row only repeats the trial length and is no cut.

    A best estimate outside its own window is a typo of the source (the data README
    lists two, 86_05 ``[3881, 3840, 4000]`` and 86_06 ``[1540, 1685, 1628]``, each one
    digit away from the window's middle): the window the annotators marked is kept and
    its middle becomes the best estimate, which is what the annotators' best estimates
    are elsewhere (86 of the 104 cuts of these labels have ``end_mid`` within 25 frames,
    0.2 s, of the middle of ``[end_lo, end_hi]``). Sorting the three numbers instead
    would make a window edge the best estimate and the typo an edge of the window.
    """
    path = Path(path)
    cols = ("end_lo", "end_mid", "end_hi")
    rows = [[_int(path, n, r, c) for c in cols] for n, r in _rows(path, cols)]
    if not rows:
        raise LabelError(f"{path}: no segments")
    windows = np.asarray(rows[:-1], dtype=np.int64).reshape(-1, 3)
    lo = windows[:, [0, 2]].min(axis=1)
    hi = windows[:, [0, 2]].max(axis=1)
    mid = windows[:, 1]
    mid = np.where((mid < lo) | (mid > hi), (lo + hi) // 2, mid)
    return np.stack([lo, mid, hi], axis=1)


# Baak's interval starts and ends closer than this (s) are one boundary (its README).
BAAK_MERGE_S = 0.5


def baak_truth(spans: list[tuple[int, int]], *, fps: float = CMU_FPS) -> np.ndarray:
    """True cuts from Baak's sparse, possibly overlapping intervals of one take.

    ``spans`` are ``(start_frame, end_frame)``, 1-based inclusive AMC frames. Every start
    (0-based frame ``start - 1``) and every end (the next frame starts after it: 0-based
    ``end``) inside the take is a boundary; boundaries closer than ``BAAK_MERGE_S`` to the
    previous one are one cut, the window ``(first, mean, last)``. The take's length is its
    last labelled frame (the README), so its last end is no cut.
    """
    if not spans:
        return np.zeros((0, 3), dtype=np.int64)
    length = max(end for _, end in spans)
    marks = sorted({f for start, end in spans for f in (start - 1, end) if 0 < f < length})
    gap = BAAK_MERGE_S * fps
    groups: list[list[int]] = []
    for f in marks:
        if groups and f - groups[-1][-1] <= gap:
            groups[-1].append(f)
        else:
            groups.append([f])
    rows = [(g[0], int(round(np.mean(g))), g[-1]) for g in groups]
    return np.asarray(rows, dtype=np.int64).reshape(-1, 3)


def baak_takes(root: Path | None = None) -> list[LabelledTake]:
    """The subject-86 takes of ``labels/cmu86_baak/intervals.csv`` that have motion (their
    four channels, where present, so that both conventions score the same view; else
    the AMC), with Baak's cuts (``baak_truth``)."""
    root = Path(root) if root is not None else data_dir()
    path = root / "labels" / "cmu86_baak" / "intervals.csv"
    if not path.is_file():
        return []
    spans: dict[str, list[tuple[int, int]]] = {}
    for line, row in _rows(path, ("take", "start_frame", "end_frame")):
        spans.setdefault(row["take"], []).append((_int(path, line, row, "start_frame"),
                                                  _int(path, line, row, "end_frame")))
    cmu, out = root / "cmu", []
    for name, rows in sorted(spans.items()):
        four = cmu / "channels4d" / f"{name}.4d.txt"
        if four.is_file():
            out.append(LabelledTake(name, four, None, baak_truth(rows), "baak", "channels",
                                    path))
        elif (files := _amc_asf(name, cmu)) is not None:
            out.append(LabelledTake(name, *files, baak_truth(rows), "baak", labels=path))
    return out


LABEL_SOURCES = (("mocap6", "mocap6/segments"), ("kruger2017", "cmu86_kruger2017"))


def bvh_frames(path: Path) -> int:
    """The ``Frames:`` count in a BVH header (without reading the motion)."""
    with open(path, "rb") as fh:
        for line in fh:
            if line.strip().lower().startswith(b"frames:"):
                return int(line.split(b":", 1)[1])
    raise LabelError(f"{path}: no Frames: line")


def _amc_asf(name: str, cmu: Path) -> tuple[Path, Path] | None:
    """The take's AMC and its subject's ASF, when both are there."""
    amc, asf = cmu / "amc" / f"{name}.amc", cmu / "asf" / f"{name.split('_')[0]}.asf"
    return (amc, asf) if amc.is_file() and asf.is_file() else None


def _mocap6(path: Path, cmu: Path) -> tuple[Path, Path | None, np.ndarray] | None:
    """Motion and truth of a mocap6 take: its BVH where present, else its AMC."""
    bvh = cmu / "bvh" / f"{path.stem}.bvh"
    if bvh.is_file():
        # The label's last end_frame is the AMC's length; a converted BVH may add lines
        # before it (cgspeed: one T-pose line).
        rows = _rows(path, ("end_frame",))
        n_amc = _int(path, *rows[-1], "end_frame") if rows else 0
        return bvh, None, mocap6_truth(path, frame_offset=max(0, bvh_frames(bvh) - n_amc))
    files = _amc_asf(path.stem, cmu)
    return None if files is None else (*files, mocap6_truth(path))


def _mocap6_blocks(path: Path, cmu: Path) -> LabelledTake | None:
    """A mocap6 take labelled by its original block file: its blocks are AMC frames, so it
    needs the AMC (a converted BVH may add lines before the motion, and the block count
    fixes the AMC's length only to within a block)."""
    files = _amc_asf(path.stem, cmu)
    if files is None:
        if (cmu / "bvh" / f"{path.stem}.bvh").is_file():
            raise LabelError(f"{path}: block labels count AMC frames; add the AMC and its "
                             f"ASF, or segments/{path.stem}.csv")
        return None
    return LabelledTake(path.stem, *files, mocap6_block_truth(path), "mocap6", labels=path)


def _kruger(path: Path, cmu: Path) -> tuple[Path, Path | None, np.ndarray, str] | None:
    """Motion and truth of a subject-86 take: its AMC, else its four channels."""
    files = _amc_asf(path.stem, cmu)
    four = cmu / "channels4d" / f"{path.stem}.4d.txt"
    if files is not None:
        return *files, kruger_truth(path), "skeleton"
    if four.is_file():
        return four, None, kruger_truth(path), "channels"
    return None


def discover(root: Path | None = None, *, channels: bool = True,
             bvh: bool = True) -> tuple[list[LabelledTake], list[str]]:
    """Every labelled take under ``root``, and one line per file that was skipped.

    Labels are read from ``labels/mocap6/segments/<take>.csv`` and
    ``labels/cmu86_kruger2017/<take>.csv``; a mocap6 take without a segments CSV is read
    from its original block file ``labels/mocap6/<take>.txt`` (with its AMC). A take with
    labels but no motion, or motion but no labels, is skipped with a line saying so; so
    is one whose label file cannot be read (the line names the row and value). With
    ``channels``, each subject-86 take that has four-channel data is listed as a
    four-channel take too (also when its full AMC is there); with ``bvh`` false, an AMC
    is preferred to a BVH.
    """
    root = Path(root) if root is not None else data_dir()
    if not root.is_dir():
        raise FileNotFoundError(f"benchmark data folder not found: {root}")
    cmu, labels = root / "cmu", root / "labels"
    takes: list[LabelledTake] = []
    skipped: list[str] = []
    labelled: set[str] = set()
    for source, path in _label_files(labels):
        labelled.add(path.stem)
        try:
            found = _take_of(source, path, cmu, bvh)
        except LabelError as exc:  # the others are still worth scoring
            reason = str(exc).removeprefix(f"{path}: ")
            skipped.append(f"skipped {path.relative_to(root)}: {reason}")
            continue
        if found is None:
            skipped.append(f"skipped {path.relative_to(root)}: labels but no motion")
            continue
        takes.append(found)
        four = cmu / "channels4d" / f"{path.stem}.4d.txt"
        if channels and source == "kruger2017" and found.kind == "skeleton" and \
                four.is_file():
            takes.append(LabelledTake(path.stem, four, None, found.truth, source,
                                      "channels", path))
    for motion in sorted([*cmu.glob("amc/*.amc"), *cmu.glob("bvh/*.bvh"),
                          *cmu.glob("channels4d/*.4d.txt")]):
        if motion.name.split(".")[0] not in labelled:
            skipped.append(f"skipped {motion.relative_to(root)}: motion but no labels")
    if not channels:
        takes = [t for t in takes if t.kind == "skeleton"]
    return takes, skipped


def unlabelled_motion(root: Path | None = None) -> list[tuple[Path, Path | None]]:
    """The full-skeleton takes under ``root`` that have no segment labels: (motion, ASF)
    of each AMC whose subject's ASF is there and each BVH without an AMC of its name
    among them (``discover`` skips them). Not scored; the bench shows what the default
    detector makes of them."""
    root = Path(root) if root is not None else data_dir()
    cmu = root / "cmu"
    labelled = {t.name for t in discover(root, channels=False)[0]}
    labelled |= {path.stem for _, path in _label_files(root / "labels")}
    out: list[tuple[Path, Path | None]] = []
    for amc in sorted(cmu.glob("amc/*.amc")):
        files = _amc_asf(amc.stem, cmu)
        if amc.stem not in labelled and files is not None:
            out.append(files)
    names = {amc.stem for amc, _ in out}
    for bvh in sorted(cmu.glob("bvh/*.bvh")):
        if bvh.stem not in labelled and bvh.stem not in names:
            out.append((bvh, None))
    return out


def _label_files(labels: Path):
    """(source, label file) of each labelled take: the CSVs of ``LABEL_SOURCES``, then the
    original mocap6 block files of takes that have no CSV."""
    stems = set()
    for source, folder in LABEL_SOURCES:
        for path in sorted((labels / folder).glob("*.csv")):
            stems.add(path.stem)
            yield source, path
    for path in sorted((labels / "mocap6").glob("*.txt")):
        if path.stem not in stems:
            yield "mocap6", path


def _take_of(source: str, path: Path, cmu: Path, bvh: bool) -> LabelledTake | None:
    if path.suffix == ".txt":
        return _mocap6_blocks(path, cmu)
    if source == "mocap6":
        found = _mocap6(path, cmu) if bvh else _mocap6_amc(path, cmu)
        return None if found is None else LabelledTake(path.stem, *found, source,
                                                       labels=path)
    found = _kruger(path, cmu)
    if found is None:
        return None
    motion, asf, truth, kind = found
    return LabelledTake(path.stem, motion, asf, truth, source, kind, path)


def _mocap6_amc(path: Path, cmu: Path):
    """As ``_mocap6``, the AMC first."""
    files = _amc_asf(path.stem, cmu)
    if files is not None:
        return *files, mocap6_truth(path)
    return _mocap6(path, cmu)


def labelled_takes(root: Path | None = None, *, bvh: bool = True,
                   channels: bool = False) -> list[LabelledTake]:
    """The labelled takes under ``root`` (see :func:`discover`), full-skeleton ones only
    unless ``channels``."""
    return discover(root, channels=channels, bvh=bvh)[0]
