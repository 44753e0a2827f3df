"""Every benchmark the runner knows, by name: the module whose ``main()`` runs it, the
arguments of its recorded run, and one line on what it measures.

A new benchmark is a module in the subpackage of its subject (``quality``, ``io``,
``service``, ``library``) with a ``main()`` that parses ``sys.argv[1:]`` and prints its
table, and an entry here; ``python -m benchmarks NAME`` then runs it and records its
output to ``benchmarks/results/NAME.md``. Add its name to ``make bench`` (the Makefile's
``BENCHES``) when it is cheap enough to rerun with every change.
"""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Benchmark:
    module: str
    about: str
    args: tuple[str, ...] = ()


def _similar(about, *args):
    return Benchmark("benchmarks.library.similar_search", about, ("--seed", "35", *args))


BENCHMARKS = {
    # quality: how well the detector cuts, and how fast motionlib reads and detects
    "quality": Benchmark("benchmarks.quality.cli", "every segmenter on every labelled take, "
                         "with leave-one-take-out rows", ("--loo",)),
    "learning-curve": Benchmark("benchmarks.quality.cli", "how a studio's cut model learns "
                                "from reviewed takes", ("learning-curve",)),
    "speed-io": Benchmark("benchmarks.quality.cli", "motionlib's read + forward kinematics "
                          "speed", ("speed", "io")),
    "speed-adapt": Benchmark("benchmarks.quality.cli", "adapted detection and fitting speed",
                             ("speed", "adapt")),
    "points-quality": Benchmark("benchmarks.quality.points", "every segmenter on the "
                                "labelled point takes"),
    # io: reading capture files
    "points-read": Benchmark("benchmarks.io.points_read", "C3D against BVH of as many "
                             "values, and other C3D readers"),
    "fbx-read": Benchmark("benchmarks.io.fbx_read", "an FBX take read against its BVH"),
    "gltf-export": Benchmark("benchmarks.io.gltf_export", "glTF export of clips without a "
                             "mesh, Blender's exporter against motionlib's writer"),
    "hostile-inputs": Benchmark("benchmarks.io.hostile_inputs", "time and memory to read "
                                "or refuse hostile capture files"),
    # service: the running service, end to end
    "upload-to-candidates": Benchmark("benchmarks.service.upload_to_candidates",
                                      "a 5-minute take from upload to cuts"),
    "fbx": Benchmark("benchmarks.service.fbx", "FBX upload to cuts, and FBX / glTF export"),
    "hour-take": Benchmark("benchmarks.service.hour_take", "an hour-long take end to end"),
    "hour-detect": Benchmark("benchmarks.service.hour_detect", "detection of the hour-long "
                             "take with and without stored positions"),
    "bulk-import": Benchmark("benchmarks.service.bulk_import", "manage.py import_captures "
                             "of 12 five-minute takes with one and two workers",
                             ("--takes", "12", "--checks", "header")),
    "capture-list-load": Benchmark("benchmarks.service.capture_list_load", "the capture "
                                   "list under load on PostgreSQL"),
    "submit-points": Benchmark("benchmarks.service.submit_points", "a review submit of a "
                               "1,000-point take: the request now and before, and the job",
                               ("--frames", "1600")),
    "review-long-take": Benchmark("benchmarks.service.review_long_take", "review requests "
                                  "on a one-hour take"),
    "review-poses": Benchmark("benchmarks.service.review_long_take", "the hour-long take "
                              "opened in Chromium: first pose and every pose, JSON chunks "
                              "against the streamed float32 poses",
                              ("--browser", "--browser-repeats", "3")),
    "review-playback": Benchmark("benchmarks.service.review_playback", "the review page's "
                                 "redraw interval and scrub latency on 38-s, 10- and "
                                 "60-minute takes, the old front end against the new"),
    "annotation-import": Benchmark("benchmarks.service.annotation_import", "an hour-long "
                                   "take's labels imported, against edit by edit"),
    "retrain": Benchmark("benchmarks.service.retrain", "retraining a project's cut model"),
    "proposals-cost": Benchmark("benchmarks.service.proposals_cost", "an annotator's own "
                                "proposed labels for a 60-minute take"),
    "poisoning": Benchmark("benchmarks.service.poisoning", "one annotator against a "
                           "project's model"),
    "soak": Benchmark("benchmarks.service.soak", "the embedded default under mixed load "
                      "while its worker is killed", ("--minutes", "30")),
    # library: the segment library's list and similar-clip search
    "library-list": Benchmark("benchmarks.library.listing", "the library list on a million "
                              "segments, SQLite", ("--busy", "3")),
    "library-attribute-filter": Benchmark("benchmarks.library.attribute_filter", "the "
                                          "library list filtered by a segment attribute, "
                                          "200,000 segments, SQLite"),
    "library-list-100k": Benchmark("benchmarks.library.listing", "the library list on "
                                   "100,000 segments, SQLite",
                                   ("--segments", "100000", "--busy", "3")),
    "library-list-postgres": Benchmark("benchmarks.library.listing", "the library list on "
                                       "100,000 segments, PostgreSQL",
                                       ("--postgres", "--segments", "100000", "--busy", "3")),
    "library-list-postgres-1m": Benchmark("benchmarks.library.listing", "the library list "
                                          "on a million segments, PostgreSQL",
                                          ("--postgres", "--segments", "1000000", "--seed",
                                           "35", "--busy", "3")),
    "similar-search": _similar("similar-clip search over a million segments"),
    "similar-search-busy": _similar("similar-clip search beside 3 busy processes",
                                    "--busy", "3"),
    "similar-search-workers": _similar("similar-clip search beside 3 busy workers (nice 10)",
                                       "--busy", "3", "--busy-nice", "10"),
    "similar-search-cold": _similar("similar-clip search from an empty page cache",
                                    "--drop-caches"),
    "index-libraries": Benchmark("benchmarks.library.index_libraries", "vector index "
                                 "libraries on the million profiles", ("--queries", "300")),
    "similar-labels": Benchmark("benchmarks.library.similar_labels", "does the nearest "
                                "clip show the same action (CMU)"),
    "points-similar": Benchmark("benchmarks.library.points_similar", "similar clips and "
                                "suggestions on bare points (vMCI)"),
}
