"""Annotations as files for the tools around Cutroom: CSV, ELAN ``.eaf``, Label Studio JSON
(``motionlib.io.annotations`` writes them), from a review, a gold version or the library.

A review or gold version gives every segment, unlabelled ones too (CSV rows and ELAN
annotations with an empty label, so that importing the file again gives back the same
cuts); Label Studio regions need a label, so it gets the labelled ones. Library segments
are labelled by definition.
"""

import io
import itertools
import zipfile
from pathlib import PurePath

import motionlib.io.annotations as fmt
from segmentation.files.exports import ZIP_ENTRY_TIME, slug

FORMATS = {"csv": ("text/csv", "csv"), "eaf": ("application/xml", "eaf"),
           "labelstudio": ("application/json", "json")}
GOLD = "gold"
# Rows of text, not clips: a bulk export may hold many more than a clip archive.
MAX_SEGMENTS = 100_000


def review_track(review):
    """The review's segments as a track named by its annotator."""
    capture = review.capture
    spans = [fmt.Span(start, stop, label) for _, start, stop, label in review.segments()]
    return fmt.Track(capture.name, review.annotator.username, capture.fps, capture.n_frames, spans)


def gold_track(gold):
    capture = gold.capture
    spans = [fmt.Span(start, stop, label) for start, stop, label in gold.segments()]
    return fmt.Track(capture.name, GOLD, capture.fps, capture.n_frames, spans)


def library_tracks(segments):
    """One track per capture and source (annotator or gold) of library segments ordered by
    capture, then source, then start (``select_related("capture", "annotator", "label")``)."""
    def source(s):
        return GOLD if s.is_gold else (s.annotator.username if s.annotator else "")

    for (_, who), group in itertools.groupby(segments, key=lambda s: (s.capture_id, source(s))):
        group = list(group)
        capture = group[0].capture
        yield fmt.Track(capture.name, who, capture.fps, capture.n_frames,
                        [fmt.Span(s.start, s.stop, s.label.name) for s in group])


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
