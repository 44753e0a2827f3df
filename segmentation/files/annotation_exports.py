"""Annotations as files for the tools around Cutroom: CSV, ELAN ``.eaf``, Label Studio JSON
(``motionlib.io.annotations`` writes them), from a review, a gold version or the library.

A review or gold version gives every segment, unlabelled ones too (CSV rows and ELAN
annotations with an empty label, so that importing the file again gives back the same
cuts); Label Studio regions need a label, so it gets the labelled ones. Library segments
are labelled by definition. The CSV carries each segment's attribute values too, one
``attribute:<name>`` column per attribute (as the library's manifest.csv does).
"""

import io
import itertools
import zipfile
from pathlib import PurePath

import motionlib.io.annotations as fmt
from segmentation.files.exports import ZIP_ENTRY_TIME, slug
from segmentation.models import GoldAttributeValue, LibraryAttributeValue, SegmentAttributeValue

FORMATS = {"csv": ("text/csv", "csv"), "eaf": ("application/xml", "eaf"),
           "labelstudio": ("application/json", "json")}
GOLD = "gold"
# Rows of text, not clips: a bulk export may hold many more than a clip archive.
MAX_SEGMENTS = 100_000


def review_track(review):
    """The review's segments as a track named by its annotator, with their attributes."""
    capture = review.capture
    frames = dict(review.kept_frames())
    values = {}
    for row in (SegmentAttributeValue.objects.filter(review=review).select_related("attribute")
                .order_by("attribute__position", "attribute_id")):
        start = 0 if row.cut_id is None else frames.get(row.cut_id)
        if start is not None:
            values.setdefault(start, []).append((row.attribute.name, row.attribute.shown(row.value)))
    spans = [fmt.Span(start, stop, label, attributes=tuple(values.get(start, ())))
             for _, start, stop, label in review.segments()]
    return fmt.Track(capture.name, review.annotator.username, capture.fps, capture.n_frames, spans)


def gold_track(gold):
    capture = gold.capture
    values = {}
    for row in (GoldAttributeValue.objects.filter(capture=capture).select_related("attribute")
                .order_by("attribute__position", "attribute_id")):
        values.setdefault(row.start, []).append((row.attribute.name, row.attribute.shown(row.value)))
    spans = [fmt.Span(start, stop, label, attributes=tuple(values.get(start, ())))
             for start, stop, label in gold.segments()]
    return fmt.Track(capture.name, GOLD, capture.fps, capture.n_frames, spans)


def library_tracks(segments):
    """One track per capture and source (annotator or gold) of library segments ordered by
    capture, then source, then start (``select_related("capture", "annotator", "label")``)."""
    def source(s):
        return GOLD if s.is_gold else (s.annotator.username if s.annotator else "")

    for (_, who), group in itertools.groupby(segments, key=lambda s: (s.capture_id, source(s))):
        group = list(group)
        capture = group[0].capture
        values = {}
        for row in (LibraryAttributeValue.objects.filter(segment__in=[s.pk for s in group])
                    .select_related("attribute").order_by("attribute__position", "attribute_id")):
            values.setdefault(row.segment_id, []).append(
                (row.attribute.name, row.attribute.shown(row.value)))
        yield fmt.Track(capture.name, who, capture.fps, capture.n_frames,
                        [fmt.Span(s.start, s.stop, s.label.name,
                                  attributes=tuple(values.get(s.pk, ()))) for s in group])


def take_stem(name):
    """A file stem for a take's annotations: "13_30" for "13_30.bvh", "take_walk" for
    "take.fbx#walk", safe characters only."""
    base, _, animation = name.partition("#")
    return slug(PurePath(base).stem + (f"_{animation}" if animation else ""))


def render(form, tracks, stem):
    """``(bytes, content type, file name)`` of ``tracks`` in ``form``. ELAN documents are
    about one take each: tracks of several takes become a zip of one ``.eaf`` per take."""
    content_type, ext = FORMATS[form]
    if form == "csv":
        return fmt.write_annotations_csv(tracks).encode(), content_type, f"{stem}.{ext}"
    if form == "labelstudio":
        return fmt.write_label_studio(tracks).encode(), content_type, f"{stem}.{ext}"
    takes = {}
    for track in tracks:
        takes.setdefault(track.take, []).append(track)
    if len(takes) == 1:
        return fmt.write_eaf(tracks).encode(), content_type, f"{stem}.{ext}"
    out = io.BytesIO()
    used = set()
    with zipfile.ZipFile(out, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for take, group in takes.items():
            name = f"{take_stem(take)}.eaf"
            while name in used:
                name = "_" + name
            used.add(name)
            info = zipfile.ZipInfo(name, date_time=ZIP_ENTRY_TIME)
            info.compress_type = zipfile.ZIP_DEFLATED
            archive.writestr(info, fmt.write_eaf(group))
    return out.getvalue(), "application/zip", f"{stem}-eaf.zip"
