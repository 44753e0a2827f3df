"""Annotation files (CSV, ELAN .eaf, Label Studio JSON) read and written by
``motionlib.io.annotations`` (issue 49), checked against an independent reader and writer
where one exists: ``pympi-ling`` for ELAN, both ways.

Label Studio's own packages are not used: ``label-studio-converter`` pulls in pandas,
nltk, lxml and requests, and ``label-studio-sdk`` opencv, pydantic and an HTTP client
(docs/annotations.md). The export below is the layout Label Studio's "JSON" export writes
for a time-series labelling project (``<TimeSeriesLabels name="label" toName="ts">``),
copied field for field, with the keys it always carries.
"""

import json

import pympi
import pytest

from motionlib.io.annotations import (
    AnnotationError,
    Span,
    Track,
    check_spans,
    read_annotations,
    select,
    write_annotations_csv,
    write_eaf,
    write_label_studio,
)
from motionlib.io.annotations.times import timecode, timecode_frames
from motionlib.shared_data import data_dir

FPS = 120.0

LABEL_STUDIO_EXPORT = [{
    "id": 17,
    "annotations": [{
        "id": 41, "completed_by": 3, "was_cancelled": False, "ground_truth": False,
        "created_at": "2026-11-30T10:12:44.019851Z", "updated_at": "2026-11-30T10:14:02.552187Z",
        "draft_created_at": None, "lead_time": 77.1, "prediction": {}, "result_count": 0,
        "unique_id": "5b0c9a3e-1b8e-4d5e-9a53-3f0a7c5b2f6d", "import_id": None,
        "last_action": None, "task": 17, "project": 2, "updated_by": 3, "parent_prediction": None,
        "parent_annotation": None, "last_created_by": None,
        "result": [
            {"value": {"start": 0.0, "end": 1.7333, "instant": False, "timeserieslabels": ["walk"]},
             "id": "Xk2pQ1", "from_name": "label", "to_name": "ts", "type": "timeserieslabels",
             "origin": "manual"},
            {"value": {"start": 6.6917, "end": 10.0, "instant": False, "timeserieslabels": ["Punch"]},
             "id": "b7Rr0e", "from_name": "label", "to_name": "ts", "type": "timeserieslabels",
             "origin": "manual"},
            {"value": {"choices": ["good take"]}, "id": "c1", "from_name": "quality",
             "to_name": "ts", "type": "choices", "origin": "manual"},
        ]}],
    "drafts": [], "predictions": [],
    "data": {"ts": "/data/upload/2/5f1e9c2a-13_30.csv"},
    "meta": {}, "created_at": "2026-11-30T10:10:01.120305Z",
    "updated_at": "2026-11-30T10:14:02.577094Z", "inner_id": 1, "total_annotations": 1,
    "cancelled_annotations": 0, "total_predictions": 0, "comment_count": 0,
    "unresolved_comment_count": 0, "last_comment_updated_at": None, "project": 2,
    "updated_by": 3, "comment_authors": [],
}]


def read(text, fmt, **kwargs):
    data = text if isinstance(text, bytes) else text.encode()
    return read_annotations(data, f"file.{ {'labelstudio': 'json'}.get(fmt, fmt)}", fmt,
                            fps=kwargs.pop("fps", FPS), **kwargs)


def spans(records):
    return [(r.start, r.stop, r.label) for r in records]


def test_it_reads_an_eaf_that_pympi_wrote_tier_by_tier(tmp_path):
    eaf = pympi.Elan.Eaf()
    eaf.add_tier("moves")
    eaf.add_annotation("moves", 0, 1733, "walk")
    eaf.add_annotation("moves", 6692, 10000, "punch")
    eaf.add_linguistic_type("notes", constraints="Symbolic_Association")
    eaf.add_tier("notes", ling="notes", parent="moves")
    eaf.add_ref_annotation("notes", "moves", 500, "fast")
    eaf.add_tier("other")
    eaf.add_annotation("other", 100, 200, "x")
    path = tmp_path / "take.eaf"
    eaf.to_file(str(path))

    records = read(path.read_bytes(), "eaf")

    assert spans(select(records, take="13_30.bvh", source="moves", name="f")) == [
        (0, 208, "walk"), (803, 1200, "punch")]
    # A reference annotation takes its parent's times.
    assert spans(select(records, take="13_30.bvh", source="notes", name="f")) == [(0, 208, "fast")]
    assert [r.where for r in records if r.source == "other"] == ["tier 'other', annotation a5"]


def test_pympi_reads_the_eaf_cutroom_writes(tmp_path):
    track = Track("13_30.bvh", "alice", FPS, 2000,
                  [Span(0, 208, "walk"), Span(208, 803, None), Span(803, 2000, "punch")])
    gold = Track("13_30.bvh", "gold", FPS, 2000, [Span(0, 803, "walk")])
    path = tmp_path / "out.eaf"
    path.write_text(write_eaf([track, gold]))

    eaf = pympi.Elan.Eaf(str(path))

    assert sorted(eaf.get_tier_names()) == ["alice", "gold"]
    assert eaf.get_annotation_data_for_tier("alice") == [
        (0, 1733, "walk"), (1733, 6692, ""), (6692, 16667, "punch")]
    assert eaf.get_annotation_data_for_tier("gold") == [(0, 6692, "walk")]
    # ... and Cutroom reads its own file back to the same frames.
    assert spans(select(read(path.read_bytes(), "eaf"), take="x", source="alice", name="f")) == [
        (0, 208, "walk"), (208, 803, None), (803, 2000, "punch")]


def test_it_names_the_tier_and_annotation_of_an_unaligned_time_slot():
    text = """<?xml version="1.0" encoding="UTF-8"?>
<ANNOTATION_DOCUMENT FORMAT="3.0" VERSION="3.0"><HEADER TIME_UNITS="milliseconds"/>
<TIME_ORDER><TIME_SLOT TIME_SLOT_ID="ts1" TIME_VALUE="0"/><TIME_SLOT TIME_SLOT_ID="ts2"/></TIME_ORDER>
<TIER TIER_ID="moves" LINGUISTIC_TYPE_REF="lt"><ANNOTATION><ALIGNABLE_ANNOTATION
 ANNOTATION_ID="a9" TIME_SLOT_REF1="ts1" TIME_SLOT_REF2="ts2"><ANNOTATION_VALUE>walk</ANNOTATION_VALUE>
</ALIGNABLE_ANNOTATION></ANNOTATION></TIER></ANNOTATION_DOCUMENT>"""
    with pytest.raises(AnnotationError, match=r"file.eaf: tier 'moves', annotation a9: its time slot has no time"):
        read(text, "eaf")


@pytest.mark.parametrize("text, message", [
    ("<ANNOTATION_DOCUMENT><TIER", r"file.eaf: line 1, column \d+: not well-formed XML"),
    ("<html/>", "is a 'html', not an ELAN ANNOTATION_DOCUMENT"),
    ('<!DOCTYPE x [<!ENTITY a "aaaa">]><ANNOTATION_DOCUMENT/>', "DOCTYPE or entity declaration"),
])
def test_it_refuses_what_is_no_elan_document(text, message):
    with pytest.raises(AnnotationError, match=message):
        read(text, "eaf")


def test_it_reads_every_column_form_of_a_csv():
    text = ("take;label;start_timecode;end_timecode\n"
            "13_30;walk;00:00:00:000;00:00:01:088\n"
            "13_30;punch;00:00:06:083;00:00:10:000\n")
    assert spans(read(text, "csv")) == [(0, 208, "walk"), (803, 1200, "punch")]
    text = "take,start_seconds,end_seconds,label\n13_30,0,1.7333,walk\n13_30,6.6917,10,punch\n"
    assert spans(read(text, "csv")) == [(0, 208, "walk"), (803, 1200, "punch")]
    # Plain start/end: whole numbers are frames, decimals or "s" seconds, a:b:c:d timecode.
    text = "# exported by hand\ntake,start,end,label\n13_30,0,1.7333,walk\n13_30,803,10s,punch\n" \
           "13_30,00:00:10:000,00:00:11:000,\n"
    assert spans(read(text, "csv")) == [(0, 208, "walk"), (803, 1200, "punch"), (1200, 1320, None)]


def test_it_names_every_bad_csv_line():
    text = ("take,label,start_frame,end_frame\n13_30,walk,0,100\n13_30,walk,1.5,200\n\n"
            "13_30,walk,300,\n13_30,walk,400,500,600\n")
    with pytest.raises(AnnotationError) as caught:
        read(text, "csv")
    assert caught.value.problems == [
        "line 3: start_frame: '1.5' is not a whole frame number",
        "line 5: end_frame is empty",
        "line 6: 5 cells, but the header names 4 columns",
    ]


def test_it_says_which_columns_a_csv_header_lacks():
    with pytest.raises(AnnotationError, match=r"line 1: the header has no start or end column "
                                              r"\(it has 'take', 'label', 'from', 'to'\)"):
        read("take,label,from,to\n13_30,walk,0,10\n", "csv")


def test_a_timecode_frame_field_must_be_below_the_rate():
    with pytest.raises(AnnotationError, match="line 2: start: 00:00:01:120: frames must be below 120"):
        read("start,end,label\n00:00:01:120,00:00:02:000,walk\n", "csv")
    assert timecode_frames(timecode(123_456, 29.97), 29.97) == 123_456


def test_it_reads_label_studio_time_series_regions_of_the_named_take():
    records = read(json.dumps(LABEL_STUDIO_EXPORT), "labelstudio")
    # One task: about any take; the choices result is not a segment.
    assert spans(records) == [(0, 208, "walk"), (803, 1200, "Punch")]
    assert records[0].source == "task 17, annotation 41 by user 3"
    assert records[1].where == "task 17, annotation 41, result 'b7Rr0e'"

    two = LABEL_STUDIO_EXPORT + [{**LABEL_STUDIO_EXPORT[0], "id": 18,
                                  "data": {"ts": "/data/upload/2/0a1b2c3d-13_29.csv"}}]
    chosen = select(read(json.dumps(two), "labelstudio"), take="13_29.bvh",
                    source="task 18, annotation 41 by user 3", name="f")
    assert spans(chosen) == [(0, 208, "walk"), (803, 1200, "Punch")]
    with pytest.raises(AnnotationError, match="no annotation of f is for take '86_01.bvh'"):
        select(read(json.dumps(two), "labelstudio"), take="86_01.bvh",
               source="task 18, annotation 41 by user 3", name="f")


def test_a_label_studio_source_names_who_completed_it_when_the_export_says():
    export = [{"id": 1, "data": {}, "annotations": [
        {"id": 2, "completed_by": {"id": 3, "email": "ann@studio.org"}, "result": []},
        {"id": 4, "completed_by": 5, "result": []}, {"id": 6, "result": []}]}]
    for number in (2, 4, 6):
        export[0]["annotations"][number // 2 - 1]["result"] = [{"id": "r", "type": "labels", "value": {
            "start": number, "end": number + 1, "labels": ["walk"]}}]
    assert [r.source for r in read(json.dumps(export), "labelstudio")] == [
        "task 1, annotation 2 by ann@studio.org", "task 1, annotation 4 by user 5", "task 1, annotation 6"]


def test_it_reads_label_studio_frames_and_video_timeline_ranges():
    export = [{"id": 1, "data": {"video": "take.mp4"}, "annotations": [{"id": 2, "result": [
        {"id": "v", "type": "timelinelabels", "value": {
            "ranges": [{"start": 1, "end": 30}, {"start": 61, "end": 90}], "timelinelabels": ["walk"]}},
        {"id": "t", "type": "timeserieslabels", "value": {"start": 100, "end": 140, "timeserieslabels": ["run"]}},
    ]}]}]
    assert spans(read(json.dumps(export), "labelstudio", unit="frames")) == [
        (0, 30, "walk"), (60, 90, "walk"), (100, 140, "run")]


def test_it_names_the_result_of_a_bad_label_studio_region():
    export = json.loads(json.dumps(LABEL_STUDIO_EXPORT))
    export[0]["annotations"][0]["result"][0]["value"]["timeserieslabels"] = ["walk", "run"]
    export[0]["annotations"][0]["result"][1]["value"]["end"] = "late"
    with pytest.raises(AnnotationError) as caught:
        read(json.dumps(export), "labelstudio")
    assert caught.value.problems == [
        "task 17, annotation 41, result 'Xk2pQ1': timeserieslabels must hold exactly one label "
        "(a segment carries one), got \"['walk', 'run']\"",
        "task 17, annotation 41, result 'b7Rr0e': end must be a number, got 'late'",
    ]


@pytest.mark.parametrize("writer, fmt", [(write_annotations_csv, "csv"), (write_eaf, "eaf"),
                                         (write_label_studio, "labelstudio")])
def test_every_format_reads_back_what_it_wrote(writer, fmt):
    labelled = [Span(0, 208, "walk"), Span(803, 1200, "=HYPERLINK(1)"), Span(1500, 1997, "punch")]
    with_gaps = labelled if fmt == "labelstudio" else [*labelled, Span(1200, 1500, None)]
    text = writer([Track("13_30.bvh", "bob", 119.88, 1997, with_gaps)])
    records = select(read(text, fmt, fps=119.88), take="13_30.bvh", source=None, name="f")
    assert spans(check_spans(records, n_frames=1997, name="f")) == spans(
        sorted(with_gaps, key=lambda s: s.start))


def test_it_lists_segments_that_overlap_or_leave_the_take():
    bad = [Span(0, 100, "a", "line 2"), Span(90, 120, "b", "line 3"), Span(50, 40, "c", "line 4"),
           Span(300, 500, "d", "line 5")]
    with pytest.raises(AnnotationError) as caught:
        check_spans(bad, n_frames=400, name="f.csv")
    assert caught.value.problems == [
        "line 4: end (frame 40) is not after start (frame 50)",
        "line 5: frames 300..500 are outside the take (0..400, end exclusive)"]
    with pytest.raises(AnnotationError, match=r"line 3 \(frames 90..120\) overlaps line 2"):
        check_spans(bad[:2], n_frames=400, name="f.csv")


def test_a_real_labelling_with_overlapping_intervals_is_refused_by_line():
    """Baak's labelling of CMU 86_01 marks a turn inside a move: a take's segments cannot
    overlap, so the import names both lines instead of guessing."""
    path = data_dir() / "labels" / "cmu86_baak" / "intervals.csv"
    if not path.is_file():
        pytest.skip(f"real labels not found at {path}")
    records = read(path.read_bytes(), "csv")
    take = select(records, take="86_01.bvh", source=None, name="intervals.csv")
    assert {r.takes for r in take} == {("86_01",)}
    with pytest.raises(AnnotationError, match=r"intervals.csv: line 3 \(frames 417..553\) "
                                              r"overlaps line 2 \(frames 28..484\)"):
        check_spans(take, n_frames=10_000, name="intervals.csv")


@pytest.mark.parametrize("name, fmt, data, message", [
    ("deep.json", "labelstudio", b"[" * 100_000 + b"]" * 100_000,
     "deep.json: nested too deeply to be a Label Studio export"),
    ("big.csv", "csv", b"start,end,label\n0,10,x\n0,10," + b"x" * 200_000 + b"\n",
     "big.csv: line 3: field larger than field limit (131072)"),
    ("nul.csv", "csv", b"start,end,label\n0,10,wa\x00lk\n",
     r"nul.csv: line 2: the label 'wa\x00lk' is not a name"),
    ("late.eaf", "eaf", b"<!--" + b"x" * 5000 + b'--><!DOCTYPE a [<!ENTITY e "x">]><ANNOTATION_DOCUMENT/>',
     "late.eaf: has a DOCTYPE or entity declaration"),
])
def test_hostile_files_are_refused_with_their_reason(name, fmt, data, message):
    """Each of these raised something other than an AnnotationError (a RecursionError, the
    csv module's error) or passed a NUL into names the database stores."""
    with pytest.raises(AnnotationError) as caught:
        read_annotations(data, name, fmt, fps=FPS)
    assert str(caught.value).startswith(message)
