"""Segment annotations as other tools keep them: CSV, ELAN ``.eaf`` and Label Studio JSON.

A file becomes :class:`Record` s, each a labelled span ``[start, stop)`` in the take's frames
(0-based, ``stop`` exclusive, as everywhere in Cutroom) with the place it came from
(``where``: "line 4", "tier 'moves', annotation a7", …), the take it names (if the file
names one) and its ``source`` (an ELAN tier, a Label Studio annotation, a CSV ``annotator``
value). A file may hold several sources; a take's review is one of them
(:func:`select`), checked against the take by :func:`check_spans`.

Writing goes the other way: :class:`Track` s (one take, one source, its spans) become one
file of the chosen format.

Every problem is an :class:`AnnotationError` naming the file and each bad line, annotation
or result; nothing here knows about projects, labels in use or users.
"""

from __future__ import annotations

import re

from motionlib.errors import shorten
from motionlib.io.annotations.csvfile import read_annotations_csv, write_annotations_csv
from motionlib.io.annotations.eaf import read_eaf, write_eaf
from motionlib.io.annotations.labelstudio import read_label_studio, write_label_studio
from motionlib.io.annotations.model import (
    FORMATS,
    AnnotationError,
    Record,
    Span,
    Track,
    check_spans,
    fail,
    matches_take,
    select,
    sources_of,
)

__all__ = ["FORMATS", "AnnotationError", "Record", "Span", "Track", "check_spans",
           "format_of", "matches_take", "read_annotations", "read_annotations_csv",
           "read_eaf", "read_label_studio", "select", "sources_of", "write_annotations_csv",
           "write_eaf", "write_label_studio"]

MAX_NAME = 200
CONTROL = re.compile(r"[\x00-\x1f\x7f]")
EXTENSIONS = {".csv": "csv", ".tsv": "csv", ".txt": "csv", ".eaf": "eaf", ".json": "labelstudio"}


def format_of(name: str, fmt: str | None = None) -> str:
    """The format of file ``name``: ``fmt`` when given (checked), else by its extension."""
    if fmt:
        if fmt not in FORMATS:
            raise AnnotationError(f"format: {fmt!r} is not an annotation format; choose one "
                                  f"of {', '.join(FORMATS)}")
        return fmt
    ext = "." + name.rsplit(".", 1)[-1].lower() if "." in name else ""
    if ext not in EXTENSIONS:
        raise AnnotationError(f"{name}: cannot tell the format from the extension {ext!r}; "
                              "use .csv, .eaf or .json (Label Studio), or name the format")
    return EXTENSIONS[ext]


def read_annotations(data: bytes, name: str, fmt: str, *, fps: float,
                     unit: str = "seconds") -> list[Record]:
    """Every record of an annotation file of format ``fmt`` (see :data:`FORMATS`).

    ``fps`` turns seconds, milliseconds and timecode into the take's frames; ``unit`` is
    what Label Studio's ``start``/``end`` count ("seconds" or "frames").
    """
    text = decode(data, name)
    if fmt == "csv":
        records = read_annotations_csv(text, name=name, fps=fps)
    elif fmt == "eaf":
        records = read_eaf(text, name=name, fps=fps)
    else:
        records = read_label_studio(text, name=name, fps=fps, unit=unit)
    return check_names(records, name)


def check_names(records: list[Record], name: str) -> list[Record]:
    """``records`` if every label and source is printable text of at most
    :data:`MAX_NAME` characters (a label is a name people read, and it is logged);
    AnnotationError lists the others by their place."""
    problems = []
    for r in records:
        for what, value in (("label", r.label), ("source", r.source)):
            if value and (len(value) > MAX_NAME or CONTROL.search(value)):
                problems.append(f"{r.where}: the {what} {shorten(value)} is not a name "
                                f"(control characters, or more than {MAX_NAME} characters)")
    if problems:
        fail(name, problems)
    return records


def decode(data: bytes, name: str) -> str:
    """UTF-8 text of ``data`` without a byte-order mark (spreadsheets write one)."""
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise AnnotationError(f"{name}: byte {exc.start} is not UTF-8 text; save the file "
                              "as UTF-8") from None
