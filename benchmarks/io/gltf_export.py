"""glTF export of clips without a mesh: Blender's exporter (OLD, how every such clip was
written before) against motionlib's own writer (NEW, :mod:`motionlib.io.gltf`), in the same
run, through the library's download endpoints.

A scratch installation on the embedded default (SQLite, local files) holds two CMU captures of
subject 13 ingested by the service's own task functions: ``13_29.bvh`` and ``13_17.amc`` (with
``13.asf``), and 27 library segments of 2 s (240 frames at 120 fps) on each, starting every
160 frames (they overlap; both takes are about 38 s): 54 clips. Django's
test client, logged in as the segments' owner, then asks for

- one clip: ``GET /api/segments/<pk>/export.glb`` (the library's "glTF" download), and
- a bulk zip of the 54: ``GET /api/segments/export.zip?file_format=glb`` (its "export all"),
  read to the end,

once with each writer. OLD puts the previous code back for the run (each clip a new armature
keyed in the Blender child and exported by Blender's glTF exporter; Blender started before the
timings, its start-up stated apart); NEW is the shipped code. Both archives must hold the same
entries and manifest, and every NEW clip's joints must be where the OLD one's are (compared
by node name after forward kinematics of each file's own nodes).

    .venv/bin/python -m benchmarks gltf-export -- [--repeats 5] [--blender-repeats 3]

OLD's zip is downloaded once (about two minutes at load 12), each other case ``--repeats``
or ``--blender-repeats`` times, after no warm-up: the first NEW run pays numpy's and the
writer's imports as a worker's first export would.
"""

import argparse
import contextlib
import io
import json
import os
import statistics
import struct
import sys
import time
import zipfile
from pathlib import Path

import numpy as np

from benchmarks.harness import data_dir
from benchmarks.harness.machine import machine
from benchmarks.harness.service import in_scratch_installation

CLIPS_PER_CAPTURE, CLIP_FRAMES, CLIP_STEP = 27, 240, 160  # the last ends on 4401 < 4593
TARGET_ONE_S, TARGET_ZIP_S = 1.0, 15.0


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5, help="timed runs of NEW")
    parser.add_argument("--blender-repeats", type=int, default=3,
                        help="timed one-clip runs of OLD (its zip runs once: two minutes)")
    parser.add_argument("--data", type=Path, default=data_dir())
    return parser.parse_args(sys.argv[1:])


def main():
    args = parse_args()
    cmu = args.data / "cmu"
    files = [cmu / "bvh" / "13_29.bvh", cmu / "amc" / "13_17.amc", cmu / "asf" / "13.asf"]
    missing = [str(p) for p in files if not p.is_file()]
    if missing:
        sys.exit(f"no {', '.join(missing)} (pass --data)")
    in_scratch_installation("cutroom-bench-gltf-", run, args)


def run(args, var):
    from django.test import Client

    from motionlib.io import blender as blender_module

    owner, project, segments = library(args.data / "cmu")
    client = Client()
    client.force_login(owner)
    loads = [os.getloadavg()[0]]
    started = time.perf_counter()
    blender_module.shared().start()
    startup = time.perf_counter() - started
    results = {}
    for name, repeats, zips in (("OLD", args.blender_repeats, 1),
                                ("NEW", args.repeats, args.repeats)):
        with writer(name):
            results[name] = measure(client, project, segments[0], repeats, zips)
        loads.append(os.getloadavg()[0])
    blender_module.shared().stop()
    report(args, startup, results, loads, compare(results["OLD"][2], results["NEW"][2]))


def library(cmu):
    """The owner, the project and its 54 segments (27 of 2 s on each capture)."""
    from django.contrib.auth import get_user_model
    from django.core.files.uploadedfile import SimpleUploadedFile

    from segmentation import services, tasks
    from segmentation.models import Capture, Label, LibrarySegment

    owner = get_user_model().objects.create_user("bench")
    project = services.do_create_project(owner, "glTF export")
    label = Label.objects.create(project=project, name="move")
    uploads = [(cmu / "bvh" / "13_29.bvh", None), (cmu / "amc" / "13_17.amc", cmu / "asf" / "13.asf")]
    for path, asf in uploads:
        upload = SimpleUploadedFile(path.name, path.read_bytes())
        extra = SimpleUploadedFile(asf.name, asf.read_bytes()) if asf else None
        capture, _ = services.do_upload_capture(project, owner, upload, asf=extra)
        tasks.ingest(capture.pk)
        capture = Capture.objects.get(pk=capture.pk)
        if capture.status != "ready":
            sys.exit(f"{path.name}: {capture.status} {capture.error}")
        for k in range(CLIPS_PER_CAPTURE):
            start = 1 + k * CLIP_STEP  # clear of a cgspeed T-pose frame 0; overlapping
            LibrarySegment.objects.create(
                project=project, capture=capture, annotator=owner, label=label, start=start,
                stop=start + CLIP_FRAMES, duration=CLIP_FRAMES / 120.0)
    return owner, project, list(LibrarySegment.objects.order_by("capture_id", "start"))


@contextlib.contextmanager
def writer(name):
    """NEW: the shipped code. OLD: glTF of a take without a mesh written as before, a new
    armature keyed and exported by the Blender child for each clip."""
    from motionlib.io import blender as blender_module
    from motionlib.io import export
    from motionlib.io.units import length_unit

    def through_blender(take, clips):
        metres = length_unit(take).metres
        for start, stop, out in clips:
            export._write_new_armature(take.slice(start, stop), out, "glb",
                                       blender_module.shared(), None, metres)

    shipped = export._write_glb_clips
    if name == "OLD":
        export._write_glb_clips = through_blender
    try:
        yield
    finally:
        export._write_glb_clips = shipped


def measure(client, project, segment, repeats, zips):
    """Seconds of each one-clip download and of each zip download; the last zip's bytes."""
    one, bulk, archive = [], [], b""
    for _ in range(repeats):
        started = time.perf_counter()
        response = client.get(f"/api/segments/{segment.pk}/export.glb")
        assert response.status_code == 200, response.content[:500]
        one.append(time.perf_counter() - started)
    for _ in range(zips):
        started = time.perf_counter()
        response = client.get("/api/segments/export.zip",
                              {"file_format": "glb", "project": project.pk})
        assert response.status_code == 200
        archive = b"".join(response.streaming_content)
        bulk.append(time.perf_counter() - started)
    return one, bulk, archive


def compare(old, new):
    """How the two archives agree: same entries and manifest; the largest distance (m)
    between a joint of a NEW clip and the same joint of its OLD clip, on the clip's first and
    last frames (each file's nodes posed by its own animation's keys)."""
    old, new = zipfile.ZipFile(io.BytesIO(old)), zipfile.ZipFile(io.BytesIO(new))
    names = old.namelist() == new.namelist()
    manifest = old.read("manifest.json") == new.read("manifest.json")
    clips = [n for n in new.namelist() if n.endswith(".glb")]
    for archive in (old, new):
        if "errors.txt" in archive.namelist() or len(clips) != 2 * CLIPS_PER_CAPTURE:
            sys.exit(f"an archive is not the 54 clips: {archive.namelist()[:5]} "
                     f"{archive.read('errors.txt') if 'errors.txt' in archive.namelist() else ''}")
    worst = max(_distance(old.read(n), new.read(n), frame)
                for n in clips for frame in (0, CLIP_FRAMES - 1))
    return {"entries": names, "manifest": manifest, "clips": len(clips), "worst": worst}


def _distance(old, new, frame):
    a, b = _joint_positions(old, frame), _joint_positions(new, frame)
    return max(float(np.linalg.norm(a[name] - b[name])) for name in b)


def _joint_positions(glb, frame):
    """World position of every named node on key ``frame`` of the file's first animation."""
    length, = struct.unpack_from("<I", glb, 12)
    gltf = json.loads(glb[20:20 + length])
    binary = glb[20 + length + 8:]
    nodes = [dict(n) for n in gltf["nodes"]]
    width = {"VEC3": 3, "VEC4": 4}
    for channel in gltf["animations"][0]["channels"]:
        accessor = gltf["accessors"][gltf["animations"][0]["samplers"][channel["sampler"]]
                                     ["output"]]
        n = width[accessor["type"]]
        offset = gltf["bufferViews"][accessor["bufferView"]].get("byteOffset", 0)
        offset += accessor.get("byteOffset", 0) + frame * n * 4
        value = np.frombuffer(binary, "<f4", n, offset)
        nodes[channel["target"]["node"]][channel["target"]["path"]] = value
    world, parent = {}, {c: i for i, n in enumerate(nodes) for c in n.get("children", [])}

    def matrix(i):
        if i not in world:
            n = nodes[i]
            m = np.eye(4)
            if "rotation" in n:
                m[:3, :3] = _quaternion_matrix(n["rotation"])
            m[:3, :3] = m[:3, :3] * np.asarray(n.get("scale", [1, 1, 1]))[None, :]
            m[:3, 3] = n.get("translation", [0, 0, 0])
            world[i] = (matrix(parent[i]) if i in parent else np.eye(4)) @ m
        return world[i]

    return {n["name"]: matrix(i)[:3, 3] for i, n in enumerate(nodes) if n.get("name")}


def _quaternion_matrix(q):
    x, y, z, w = q
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                     [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                     [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]])


def report(args, startup, results, loads, agree):
    print(f"glTF export of clips without a mesh, OLD (Blender's exporter) against NEW "
          f"(motionlib.io.gltf); {machine()}; load average (1 min) "
          f"{', '.join(f'{x:.1f}' for x in loads)} (start, after OLD, after NEW); "
          f"embedded default (SQLite, local files), Django's test client")
    print(f"Blender started once before OLD: {startup:.2f} s (not counted below)")
    print(f"clips: {2 * CLIPS_PER_CAPTURE} of {CLIP_FRAMES} frames (2 s at 120 fps), "
          f"{CLIPS_PER_CAPTURE} each from CMU 13_29.bvh and 13_17.amc")
    print()
    print(f"{'case':<34} {'runs':>4} {'median s':>9} {'min s':>7} {'max s':>7} {'target':>8}")
    for name, (one, bulk, _) in results.items():
        for what, times, target in (("one clip, export.glb", one, TARGET_ONE_S),
                                    ("54-clip zip, export.zip", bulk, TARGET_ZIP_S)):
            print(f"{name + ' ' + what:<34} {len(times):>4} {statistics.median(times):>9.3f} "
                  f"{min(times):>7.3f} {max(times):>7.3f} {'<= ' + str(target):>8}")
    print()
    for what, index, target in (("one clip", 0, TARGET_ONE_S), ("54-clip zip", 1, TARGET_ZIP_S)):
        old, new = (statistics.median(results[n][index]) for n in ("OLD", "NEW"))
        verdict = "ok" if new <= target else "MISSED"
        print(f"{what}: OLD / NEW {old / new:.0f}x; NEW {new:.3f} s against {target:.0f} s: "
              f"{verdict}")
    print(f"archives: same entries {'yes' if agree['entries'] else 'NO'}, same manifest "
          f"{'yes' if agree['manifest'] else 'NO'}; {agree['clips']} clips, joints "
          f"of NEW against OLD (first and last frames) within {agree['worst'] * 1000:.3f} mm")
