"""motionlib's speed benchmarks, printing tables: ``python -m benchmarks speed-io|speed-adapt``.

How well the segmenters cut is measured by ``python -m benchmarks quality`` (``bench``);
this module measures only how fast things run.

``io``: read + forward kinematics of the CMU take 13_29 as BVH and as AMC + ASF, against the
PyPI ``bvh`` package's parse of the same BVH (median of several interleaved runs, one process,
same files; the machine's load average is printed since other work skews wall times),
and peak traced memory of read + FK against the file size; plus the time to synthesise a
five-minute take.

``adapt``: the adapted default detector's speed on five-minute 120 fps synthetic takes,
for the model format the learner learns (candidate scorer; nothing learns the first
format any more, so its figures come from an older revision): detection zero-shot and
with a model (median of several runs), and fitting a model on 50 such
takes (10 distinct takes, each given five times, so the examples fit in memory; fitting
visits every example in full either way), and refitting them after one example's cuts
changed with every example's study stored (``adapt.MemoryStudies``; what the service
does after a submit), with wall and CPU time of this process and the load average, on
one BLAS thread, as Cutroom's workers run (``make up`` and compose set
``OPENBLAS_NUM_THREADS=1``): BLAS threads of its own would count their waiting as CPU
time.
"""

from __future__ import annotations

import dataclasses
import os
import statistics
import sys
import time
import tracemalloc
from pathlib import Path

from segmentation.shared_data import data_dir

TARGET_MS, TARGET_SPEEDUP, TARGET_MEMORY = 40.0, 10.0, 5.0


def _timed_rounds(cases, runs: int) -> dict[str, tuple[list[float], list[float]]]:
    """Wall and CPU milliseconds per case, the cases interleaved round by round.

    Interleaving makes every case see the same background load; the slow ``bvh`` package
    runs every fourth round only.
    """
    for _, _, fn in cases:
        fn()  # warm up caches and lazy imports
    timings = {name: ([], []) for name, _, _ in cases}
    for round_ in range(runs):
        for name, _, fn in cases:
            if "bvh package" in name and round_ % 4:
                continue
            wall, cpu = time.perf_counter(), time.process_time()
            fn()
            timings[name][0].append((time.perf_counter() - wall) * 1e3)
            timings[name][1].append((time.process_time() - cpu) * 1e3)
    return timings


def _peak_bytes(fn) -> int:
    tracemalloc.start()
    try:
        fn()
        return tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()


def _cases(cmu: Path):
    import bvh as bvh_package

    import motionlib

    bvh_file = cmu / "bvh" / "13_29.bvh"
    amc_file, asf_file = cmu / "amc" / "13_29.amc", cmu / "asf" / "13.asf"
    return [
        ("motionlib read+FK 13_29.bvh", bvh_file,
         lambda: motionlib.forward_kinematics(motionlib.read(bvh_file))),
        ("motionlib read+FK 13_29.amc", amc_file,
         lambda: motionlib.forward_kinematics(motionlib.read(amc_file, asf=asf_file))),
        ("bvh package parse 13_29.bvh", bvh_file,
         lambda: bvh_package.Bvh(bvh_file.read_text())),
    ]


def _synth_case():
    import motionlib

    return ("synth.generate 5 min @120fps", None,
            lambda: motionlib.synth.generate(seed=0, fps=120.0, duration=300.0))


def run_io(args) -> int:
    cmu = Path(args.data) / "cmu"
    if not (cmu / "bvh" / "13_29.bvh").is_file():
        print(f"benchmarks.quality speed io: error: CMU captures not found under {cmu}",
              file=sys.stderr)
        return 2
    cases = _cases(cmu)
    timings = _timed_rounds(cases, args.runs)
    # Timed on its own, after the others: its matrix product wakes BLAS threads that keep
    # spinning for a while and would slow whatever runs next on a two-core machine.
    synth = _synth_case()
    timings.update(_timed_rounds([synth], args.runs))
    rows = []
    for name, path, fn in [*cases, synth]:
        wall, cpu = timings[name]
        size = path.stat().st_size if path is not None else None
        rows.append((name, statistics.median(wall), min(wall), statistics.median(cpu), len(wall),
                     _peak_bytes(fn), size))
    _print_table(rows)
    return 0


def _print_table(rows) -> None:
    print(f"{'case':<30}{'wall ms':>9}{'min ms':>8}{'cpu ms':>8}{'runs':>6}{'peak MiB':>10}"
          f"{'file MiB':>10}{'peak/file':>10}")
    for name, median, fastest, cpu, runs, peak, size in rows:
        file_mib, ratio = (f"{size / 2**20:>10.2f}", f"{peak / size:>10.2f}") if size else \
            (f"{'-':>10}", f"{'-':>10}")
        print(f"{name:<30}{median:>9.1f}{fastest:>8.1f}{cpu:>8.1f}{runs:>6}"
              f"{peak / 2**20:>10.2f}{file_mib}{ratio}")
    ours, theirs = rows[0], rows[2]
    speedup = theirs[1] / ours[1]
    print("(wall = median elapsed time, min = fastest run, cpu = median CPU time of this "
          "process)")
    print(f"load average during the run: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    print()
    print(f"read+FK 13_29.bvh median {ours[1]:.1f} ms (target <= {TARGET_MS:.0f} ms): "
          f"{'ok' if ours[1] <= TARGET_MS else 'MISSED'}")
    print(f"speed-up over the bvh package's parse alone: {speedup:.1f}x "
          f"(target >= {TARGET_SPEEDUP:.0f}x): {'ok' if speedup >= TARGET_SPEEDUP else 'MISSED'}")
    ratio = ours[5] / ours[6]
    print(f"peak memory of read+FK 13_29.bvh: {ratio:.2f}x the file (target < "
          f"{TARGET_MEMORY:.0f}x): {'ok' if ratio < TARGET_MEMORY else 'MISSED'}")


TARGET_DETECT_S, TARGET_FIT_S = 0.5, 10.0


def _timed(fn) -> tuple[float, float, object]:
    wall, cpu = time.perf_counter(), time.process_time()
    result = fn()
    return time.perf_counter() - wall, time.process_time() - cpu, result


def run_adapt(args) -> int:
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        return _run_adapt(args)


def _run_adapt(args) -> int:
    import numpy as np

    from motionlib import adapt, synth

    minutes, distinct = args.minutes, 10
    takes = []
    for seed in range(distinct):
        take, segments = synth.generate(seed=seed, fps=120.0, duration=60.0 * minutes)
        takes.append((take, np.asarray([s[0] for s in segments[1:]])))
    examples = [takes[i % distinct] for i in range(args.takes)]
    target, _ = synth.generate(seed=99, fps=120.0, duration=60.0 * minutes)
    print(f"{'case':<58}{'wall s':>9}{'cpu s':>9}{'target s':>10}")
    print("format 2, candidate scorer (now)")
    _time_learner(adapt.fit_cut_model, examples, target, minutes, args)
    print("ok/MISSED compare the CPU time of this single-threaded process, its time on one "
          "free core;\nwall time also counts waiting for a core on a busy machine.")
    print("threads: one BLAS thread, as the workers run; "
          f"load average during the run: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    return 0


def _time_learner(fit, examples, target, minutes, args) -> None:
    from motionlib import adapt

    fit_wall, fit_cpu, model = _timed(lambda: fit(examples))
    # As the service refits after a submit: every example's study stored, one example's
    # cuts changed (its last cut removed).
    keyed = [adapt.Example(name=f"take {i}", cuts=cuts, fps=take.fps, n_frames=take.n_frames,
                           read=lambda take=take: take, key=f"take-{i}")
             for i, (take, cuts) in enumerate(examples)]
    studies = adapt.MemoryStudies()
    fit(keyed, studies=studies)
    keyed[0] = dataclasses.replace(keyed[0], cuts=keyed[0].cuts[:-1])
    refit_wall, refit_cpu, _ = _timed(lambda: fit(keyed, studies=studies))
    adapt.detect(target, model)  # warm up
    runs = [_timed(lambda: adapt.detect(target, model))[:2] for _ in range(args.runs)]
    detect_wall = statistics.median(r[0] for r in runs)
    detect_cpu = statistics.median(r[1] for r in runs)
    zero = [_timed(lambda: adapt.detect(target))[:2] for _ in range(args.runs)]
    rows = [
        (f"  detect, zero-shot, {minutes:g}-min 120 fps take",
         statistics.median(r[0] for r in zero), statistics.median(r[1] for r in zero),
         None, f"(median of {args.runs})"),
        (f"  detect, with a model, {minutes:g}-min 120 fps take", detect_wall, detect_cpu,
         TARGET_DETECT_S, f"(median of {args.runs})"),
        (f"  fit on {args.takes} {minutes:g}-min 120 fps takes, none stored", fit_wall,
         fit_cpu, TARGET_FIT_S, f"({model.n_cuts} cuts)"),
        (f"  refit, 1 of {args.takes} changed, studies stored", refit_wall, refit_cpu,
         TARGET_FIT_S, "(as after a submit)"),
    ]
    for case, wall, cpu, target_s, note in rows:
        verdict = "" if target_s is None else ("ok" if cpu <= target_s else "MISSED")
        shown = "" if target_s is None else f"{target_s:.1f}"
        print(f"{case:<58}{wall:>9.3f}{cpu:>9.3f}{shown:>10}  {verdict} {note}")


def add_speed(subparsers) -> None:
    """Register ``python -m benchmarks speed-io|speed-adapt`` (see ``cli``)."""
    parser = subparsers.add_parser(
        "speed", help="benchmark read and detection speed (prints tables)",
        description="How fast motionlib reads takes and detects cuts; the segmentation "
                    "quality is the default command.")
    sub = parser.add_subparsers(dest="benchmark", required=True, metavar="benchmark")
    io = sub.add_parser("io", help="read + FK speed and memory on CMU 13_29")
    io.add_argument("--runs", type=int, default=21, help="timed runs per motionlib case")
    io.add_argument("--data", default=str(data_dir()),
                    help="the shared data folder (default: $CUTROOM_BENCH_DATA or "
                         "../shared/data)")
    io.set_defaults(handler=run_io)
    ad = sub.add_parser("adapt", help="adapted detection and fitting speed, 5-min takes")
    ad.add_argument("--takes", type=int, default=50, help="example takes to fit on")
    ad.add_argument("--minutes", type=float, default=5.0, help="length of each take")
    ad.add_argument("--runs", type=int, default=5, help="timed detection runs")
    ad.set_defaults(handler=run_adapt)
