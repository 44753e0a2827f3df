"""Annotations as CSV: one row per segment.

The first row that is not a ``#`` comment names the columns (any case; ``,`` ``;`` or tab
between cells, as the header uses):

- ``label`` (or ``class``, required): the segment's label; empty for a segment without one;
- ``take`` (or ``capture``, ``file``), optional: which take the row is about; a file of
  several takes gives each take its own rows;
- ``annotator`` (or ``source``, ``tier``), optional: whose annotation, when a file holds
  several people's (one is imported at a time);
- the start and the end, in one of these forms (the first form present is used):

  ================================  ===========================================
  ``start_frame`` / ``end_frame``   whole frames, 0-based
  ``start_timecode`` / ``end_…``    SMPTE ``HH:MM:SS:FF`` at the take's rate
  (also ``start_tc`` / ``end_tc``)
  ``start_seconds`` / ``end_…``     seconds (also ``start_s``, ``start_sec``,
                                    ``start_time``)
  ``start`` / ``end`` (or ``stop``) per cell: a whole number is frames, a decimal
                                    number or ``2.5s`` seconds, ``a:b:c:d``
                                    timecode
  ================================  ===========================================

The end is exclusive: the segment holds frames ``start .. end - 1`` (the next segment starts
at ``end``), as Cutroom writes it. Written files carry every form, and names that a
spreadsheet would run as formulas start with ``'`` (:func:`motionlib.io.text.spreadsheet_safe`),
taken off again on reading.
"""

from __future__ import annotations

import csv
import io

from motionlib.errors import shorten
from motionlib.io.annotations.model import AnnotationError, Record, Track, fail
from motionlib.io.annotations.times import TimeError, frames_of, seconds, timecode
from motionlib.io.text import spreadsheet_safe, spreadsheet_text

LABEL = ("label", "class")
TAKE = ("take", "capture", "file")
SOURCE = ("annotator", "source", "tier")
# (form, column names) in order of preference, for the start; the end's replace "start".
FORMS = (("frame", ("start_frame",)), ("timecode", ("start_timecode", "start_tc")),
         ("seconds", ("start_seconds", "start_s", "start_sec", "start_time")),
         ("any", ("start",)))
END_WORDS = ("end", "stop")
MAX_ROWS = 200_000
COLUMNS = ["take", "annotator", "label", "start_frame", "end_frame", "start_seconds",
           "end_seconds", "start_timecode", "end_timecode"]


def read_annotations_csv(text: str, *, name: str, fps: float) -> list[Record]:
    """Every row of an annotation CSV as a :class:`Record` (``where`` is "line N")."""
    lines = text.splitlines(keepends=True)
    skip = 0
    while skip < len(lines) and (not lines[skip].strip() or lines[skip].lstrip().startswith("#")):
        skip += 1
    if skip == len(lines):
        raise AnnotationError(f"{name}: the file is empty; the first line names the columns "
                              "(take, start, end, label)")
    header = lines[skip]
    delimiter = max(",;\t", key=header.count)
    reader = csv.reader(io.StringIO("".join(lines[skip:])), delimiter=delimiter)
    try:
        return _rows(reader, name, fps, skip)
    except csv.Error as exc:
        # A cell over the csv module's size limit, a quote left open at the end…
        raise AnnotationError(f"{name}: line {reader.line_num + skip}: {exc}") from None


def _rows(reader, name, fps, skip):
    columns = [c.strip().lower().replace(" ", "_").replace("-", "_") for c in next(reader)]
    layout = _layout(columns, name, skip + 1)
    records, problems = [], []
    for row in reader:
        line = reader.line_num + skip
        if not any(cell.strip() for cell in row) or row[0].lstrip().startswith("#"):
            continue
        if len(records) + len(problems) >= MAX_ROWS:
            raise AnnotationError(f"{name}: more than {MAX_ROWS} rows; split the file")
        try:
            records.append(_record(row, layout, columns, fps, line))
        except TimeError as exc:
            problems.append(f"line {line}: {exc}")
    if problems:
        fail(name, problems)
    return records


def _layout(columns, name, line):
    """``{"label": i, "take": i|None, "source": i|None, "start": (i, form), "end": (i, form)}``."""
    def find(names):
        return next((columns.index(n) for n in names if n in columns), None)

    layout = {"label": find(LABEL), "take": find(TAKE), "source": find(SOURCE)}
    for side in ("start", "end"):
        for form, names in FORMS:
            if side == "end":
                names = tuple(n.replace("start", word) for word in END_WORDS for n in names)
            index = find(names)
            if index is not None:
                layout[side] = (index, form)
                break
    missing = [k for k in ("label", "start", "end") if layout.get(k) is None]
    if missing:
        raise AnnotationError(
            f"{name}: line {line}: the header has no {' or '.join(missing)} column (it has "
            f"{', '.join(map(shorten, columns[:12]))}); name the columns take, start, end, label "
            "(or start_frame/end_frame, start_seconds/end_seconds, start_timecode/end_timecode)")
    return layout


def _record(row, layout, columns, fps, line):
    if len(row) > len(columns):
        raise TimeError(f"{len(row)} cells, but the header names {len(columns)} columns")
    cell = lambda i: spreadsheet_text(row[i].strip()) if i is not None and i < len(row) else ""  # noqa: E731
    times = []
    for side in ("start", "end"):
        index, form = layout[side]
        text = cell(index)
        if not text:
            raise TimeError(f"{columns[index]} is empty")
        try:
            times.append(frames_of(text, form, fps))
        except TimeError as exc:
            raise TimeError(f"{columns[index]}: {exc}") from None
    take = cell(layout["take"])
    return Record(start=times[0], stop=times[1], label=cell(layout["label"]) or None,
                  where=f"line {line}", source=cell(layout["source"]),
                  takes=(take,) if take else ())


def write_annotations_csv(tracks: list[Track]) -> str:
    """One row per span of every track, in the layout :func:`read_annotations_csv` reads,
    then one ``attribute:<name>`` column per segment attribute any span carries (a yes/no
    as true/false; empty where a span has none). Reading ignores those columns."""
    tracks = list(tracks)  # read twice: the attribute names, then the rows
    names = list(dict.fromkeys(n for t in tracks for s in t.spans for n, _ in s.attributes))
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    writer.writerow(COLUMNS + [spreadsheet_safe(f"attribute:{n}") for n in names])
    for t in tracks:
        for s in t.spans:
            values = dict(s.attributes)
            writer.writerow([spreadsheet_safe(t.take), spreadsheet_safe(t.source),
                             spreadsheet_safe(s.label or ""), s.start, s.stop,
                             seconds(s.start, t.fps), seconds(s.stop, t.fps),
                             timecode(s.start, t.fps), timecode(s.stop, t.fps)]
                            + [_attribute_cell(values.get(n)) for n in names])
    return out.getvalue()


def _attribute_cell(value) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    return spreadsheet_safe(str(value))
