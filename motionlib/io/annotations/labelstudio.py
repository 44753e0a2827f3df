"""Label Studio's JSON export of time-series, audio and video labels.

The layout Label Studio's "JSON" export writes (and its import reads)::

    [{"id": 12, "data": {"ts": "/data/upload/1/ab12cd34-13_30.csv", ...},
      "annotations": [{"id": 40, "completed_by": 3, "was_cancelled": false,
                       "result": [{"id": "Xk2p", "type": "timeserieslabels",
                                   "from_name": "label", "to_name": "ts",
                                   "value": {"start": 1.25, "end": 3.5, "instant": false,
                                             "timeserieslabels": ["walk"]}}]}],
      "predictions": []}]

- a ``timeserieslabels`` (time series) or ``labels`` (audio) region has ``start`` and
  ``end`` in the time series' own units: seconds by default, or frames (row indexes) when
  the task's time column counts rows (``unit="frames"``);
- a ``timelinelabels`` (video timeline) region has ``ranges`` of 1-based frames, both ends
  inside the region: frames ``start - 1 .. end - 1`` here;
- results of other types (choices, text areas, rectangles) are not segments and are passed
  over; a region with more than one label is refused (a segment carries one).

Each annotation of each task is a source, ``"task 12, annotation 40 by user 3"`` (who
completed it, when the export says); cancelled ones are passed over. A task names its take by the file names among its ``data`` values (matched
by stem, ignoring the ``ab12cd34-`` prefix of an upload); a file of one task is about any
take.
"""

from __future__ import annotations

import json

from motionlib.errors import shorten
from motionlib.io.annotations.model import AnnotationError, Record, Track, fail
from motionlib.io.annotations.times import TimeError, seconds, seconds_frames

LABEL_KEYS = ("timeserieslabels", "labels", "timelinelabels")
UNITS = ("seconds", "frames")


def read_label_studio(text: str, *, name: str, fps: float, unit: str = "seconds") -> list[Record]:
    """Every labelled region of every (not cancelled) annotation of every task."""
    if unit not in UNITS:
        raise AnnotationError(f"unit: must be seconds or frames, got {shorten(unit)}")
    try:
        tasks = json.loads(text)
    except ValueError as exc:
        raise AnnotationError(f"{name}: not JSON ({shorten(str(exc), 80)})") from None
    except RecursionError:
        raise AnnotationError(f"{name}: nested too deeply to be a Label Studio export") from None
    if isinstance(tasks, dict):
        tasks = [tasks]
    if not isinstance(tasks, list) or not all(isinstance(t, dict) for t in tasks):
        raise AnnotationError(f"{name}: a Label Studio export is a list of tasks (objects "
                              "with data and annotations)")
    records, problems = [], []
    for number, task in enumerate(tasks):
        task_id = task.get("id", number + 1)
        takes = _takes(task.get("data")) if len(tasks) > 1 else ()
        annotations = task.get("annotations")
        if not isinstance(annotations, list):
            problems.append(f"task {task_id}: has no annotations list")
            continue
        for a_number, annotation in enumerate(annotations):
            if not isinstance(annotation, dict) or annotation.get("was_cancelled"):
                continue
            place = f"task {task_id}, annotation {annotation.get('id', a_number + 1)}"
            source = place + _who(annotation.get("completed_by"))
            results = annotation.get("result")
            if not isinstance(results, list):
                problems.append(f"{place}: has no result list")
                continue
            for r_number, result in enumerate(results):
                where = f"{place}, result {_result_id(result, r_number)}"
                try:
                    records += _records(result, fps, unit, where, source, takes)
                except TimeError as exc:
                    problems.append(f"{where}: {exc}")
    if problems:
        fail(name, problems)
    return records


def _result_id(result, number):
    rid = result.get("id") if isinstance(result, dict) else None
    return shorten(rid, 20) if rid is not None else f"#{number + 1}"


def _who(completed_by):
    """" by user 3" (an export's user id) or " by ann@studio.org" (an expanded user), so
    that the import dialog tells annotators apart; "" when the export does not say."""
    if isinstance(completed_by, dict):
        completed_by = completed_by.get("email") or completed_by.get("id")
    if isinstance(completed_by, bool) or not isinstance(completed_by, int | str) or completed_by == "":
        return ""
    return f" by user {completed_by}" if isinstance(completed_by, int) else f" by {completed_by[:60]}"


def _takes(data):
    """The file names a task's data holds (its take, as uploaded)."""
    if not isinstance(data, dict):
        return ()
    return tuple(v for v in data.values() if isinstance(v, str) and len(v) < 1000)


def _records(result, fps, unit, where, source, takes):
    if not isinstance(result, dict) or not isinstance(result.get("value"), dict):
        raise TimeError("has no value")
    value = result["value"]
    key = next((k for k in LABEL_KEYS if k in value), None)
    if key is None:
        return []  # not a labelled region (choices, text, rectangles…)
    labels = value[key]
    if not isinstance(labels, list) or len(labels) != 1 or not isinstance(labels[0], str):
        raise TimeError(f"{key} must hold exactly one label (a segment carries one), got "
                        f"{shorten(labels)}")
    if key == "timelinelabels":
        ranges = value.get("ranges")
        if not isinstance(ranges, list) or not ranges:
            raise TimeError("a timelinelabels region has no ranges")
        spans = [(_number(r, "start") - 1, _number(r, "end")) for r in ranges]
    else:
        spans = [(_number(value, "start"), _number(value, "end"))]
        spans = [(a, b) if unit == "frames" else (seconds_frames(a, fps), seconds_frames(b, fps))
                 for a, b in spans]
    return [Record(start=round(a), stop=round(b), label=labels[0].strip() or None, where=where,
                   source=source, takes=takes) for a, b in spans]


def _number(value, key):
    number = value.get(key) if isinstance(value, dict) else None
    if isinstance(number, bool) or not isinstance(number, int | float):
        raise TimeError(f"{key} must be a number, got {shorten(number)}")
    if number != number or abs(number) > 2**53:
        raise TimeError(f"{key} must be a finite number, got {number}")
    return number


def write_label_studio(tracks: list[Track]) -> str:
    """The tracks as a Label Studio JSON export: one task per take, one annotation per
    source, one ``timeserieslabels`` region per labelled span (seconds)."""
    tasks, by_take = [], {}
    for track in tracks:
        task = by_take.get(track.take)
        if task is None:
            task = {"id": len(tasks) + 1, "data": {"take": track.take, "fps": track.fps,
                                                    "frames": track.n_frames},
                    "annotations": [], "predictions": []}
            by_take[track.take] = task
            tasks.append(task)
        result = [{"id": f"r{i + 1}", "type": "timeserieslabels", "from_name": "label",
                   "to_name": "ts", "origin": "manual",
                   "value": {"start": seconds(s.start, track.fps), "end": seconds(s.stop, track.fps),
                             "instant": False, "timeserieslabels": [s.label]}}
                  for i, s in enumerate(track.spans) if s.label]
        task["annotations"].append({"id": len(task["annotations"]) + 1,
                                    "was_cancelled": False, "result": result})
    return json.dumps(tasks, indent=1, ensure_ascii=False) + "\n"
