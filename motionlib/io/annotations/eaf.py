"""ELAN annotation documents (``.eaf``, EAF 2.x/3.0 XML).

Reading: every tier is a source; an annotation is a span from its two time slots
(milliseconds, ``round(ms * fps / 1000)`` frames). A reference annotation (a tier that
depends on another) takes its times from the annotation it refers to. An annotation whose
time slot has no time (ELAN's unaligned slots) is refused by its tier and id. The document
is about one take: its media is not matched against the capture's name (media files are
video or audio, named as the studio likes).

Writing: one tier per track (its source), of one linguistic type ``cutroom-segments``,
time-alignable; times in milliseconds. ELAN and ``pympi-ling`` read it.

XML is read with the standard library's parser, which resolves no external entity;
``DOCTYPE`` declarations are refused outright (an EAF file has none), so no entity
expansion can blow up.
"""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET
from datetime import UTC, datetime

from motionlib.errors import shorten
from motionlib.io.annotations.model import AnnotationError, Record, Track, fail
from motionlib.io.annotations.times import seconds_frames

LINGUISTIC_TYPE = "cutroom-segments"
DOCTYPE = re.compile(r"<!DOCTYPE|<!ENTITY", re.IGNORECASE)


def read_eaf(text: str, *, name: str, fps: float) -> list[Record]:
    """Every annotation of every tier, ``source`` = the tier's id, ``where`` = "tier 'T',
    annotation a7"."""
    root = _parse(text, name)
    slots = {}
    for slot in root.iter("TIME_SLOT"):
        value = slot.get("TIME_VALUE")
        slots[slot.get("TIME_SLOT_ID")] = int(value) if value and value.isdigit() else None
    times, refs, found, problems = {}, {}, [], []
    for tier in root.iter("TIER"):
        tier_id = tier.get("TIER_ID") or ""
        for annotation in tier.iter("ANNOTATION"):
            for child in annotation:
                where = f"tier {tier_id!r}, annotation {child.get('ANNOTATION_ID')}"
                value = (child.findtext("ANNOTATION_VALUE") or "").strip() or None
                found.append((child.get("ANNOTATION_ID"), tier_id, value, where))
                if child.tag == "ALIGNABLE_ANNOTATION":
                    ends = [slots.get(child.get(k), "missing") for k in ("TIME_SLOT_REF1", "TIME_SLOT_REF2")]
                    if any(e is None or e == "missing" for e in ends):
                        problems.append(f"{where}: its time slot has no time (unaligned in ELAN); "
                                        "align it or leave it out")
                        continue
                    times[child.get("ANNOTATION_ID")] = tuple(ends)
                elif child.tag == "REF_ANNOTATION":
                    refs[child.get("ANNOTATION_ID")] = child.get("ANNOTATION_REF")
    records = []
    for annotation_id, tier_id, value, where in found:
        ms = _time_of(annotation_id, times, refs)
        if ms is None:
            if annotation_id not in times and annotation_id in refs:
                problems.append(f"{where}: refers to annotation {refs[annotation_id]!r}, "
                                "which has no times")
            continue
        records.append(Record(start=seconds_frames(ms[0] / 1000, fps),
                              stop=seconds_frames(ms[1] / 1000, fps), label=value, where=where,
                              source=tier_id))
    if problems:
        fail(name, problems)
    return records


def tiers(text: str, *, name: str) -> list[str]:
    """The tier ids of a document, in file order (also tiers without annotations)."""
    return [t.get("TIER_ID") or "" for t in _parse(text, name).iter("TIER")]


def _parse(text, name):
    if DOCTYPE.search(text):
        raise AnnotationError(f"{name}: has a DOCTYPE or entity declaration, which an ELAN "
                              "file never has")
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, column = exc.position
        raise AnnotationError(f"{name}: line {line}, column {column}: not well-formed XML "
                              f"({shorten(str(exc), 80)})") from None
    if root.tag != "ANNOTATION_DOCUMENT":
        raise AnnotationError(f"{name}: the document is a {shorten(root.tag)}, not an ELAN "
                              "ANNOTATION_DOCUMENT")
    units = root.find("HEADER")
    if units is not None and units.get("TIME_UNITS", "milliseconds") != "milliseconds":
        raise AnnotationError(f"{name}: TIME_UNITS is {units.get('TIME_UNITS')!r}; only "
                              "milliseconds are read")
    return root


def _time_of(annotation_id, times, refs, depth=0):
    """The (start, end) in ms of an annotation, following references up to their parent."""
    while annotation_id not in times and annotation_id in refs and depth < 50:
        annotation_id, depth = refs[annotation_id], depth + 1
    return times.get(annotation_id)


def write_eaf(tracks: list[Track], *, author: str = "Cutroom",
              media: str = "", now: datetime | None = None) -> str:
    """The tracks (one take, one tier each) as an EAF 3.0 document."""
    now = now or datetime.now(UTC)
    root = ET.Element("ANNOTATION_DOCUMENT", {
        "AUTHOR": author, "DATE": now.isoformat(timespec="seconds"), "FORMAT": "3.0",
        "VERSION": "3.0", "xmlns:xsi": "http://www.w3.org/2001/XMLSchema-instance",
        "xsi:noNamespaceSchemaLocation": "http://www.mpi.nl/tools/elan/EAFv3.0.xsd"})
    header = ET.SubElement(root, "HEADER", {"MEDIA_FILE": "", "TIME_UNITS": "milliseconds"})
    if media:
        ET.SubElement(header, "MEDIA_DESCRIPTOR", {"MEDIA_URL": media, "MIME_TYPE": "unknown"})
    count = sum(len(t.spans) for t in tracks)
    ET.SubElement(header, "PROPERTY", {"NAME": "lastUsedAnnotationId"}).text = str(count)
    order = ET.SubElement(root, "TIME_ORDER")
    slot, annotation = 0, 0
    tier_elements = []
    for track in tracks:
        tier = ET.Element("TIER", {"TIER_ID": track.source, "LINGUISTIC_TYPE_REF": LINGUISTIC_TYPE})
        for span in track.spans:
            refs = []
            for frame in (span.start, span.stop):
                slot += 1
                ET.SubElement(order, "TIME_SLOT", {"TIME_SLOT_ID": f"ts{slot}",
                                                   "TIME_VALUE": str(round(frame * 1000 / track.fps))})
                refs.append(f"ts{slot}")
            annotation += 1
            outer = ET.SubElement(tier, "ANNOTATION")
            inner = ET.SubElement(outer, "ALIGNABLE_ANNOTATION", {
                "ANNOTATION_ID": f"a{annotation}", "TIME_SLOT_REF1": refs[0], "TIME_SLOT_REF2": refs[1]})
            ET.SubElement(inner, "ANNOTATION_VALUE").text = span.label or ""
        tier_elements.append(tier)
    root.extend(tier_elements)
    ET.SubElement(root, "LINGUISTIC_TYPE", {"LINGUISTIC_TYPE_ID": LINGUISTIC_TYPE,
                                            "TIME_ALIGNABLE": "true", "GRAPHIC_REFERENCES": "false"})
    ET.indent(root)
    return '<?xml version="1.0" encoding="UTF-8"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
