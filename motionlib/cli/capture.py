"""The ``info`` and ``convert`` commands: a capture file described, or written as BVH."""

from __future__ import annotations

from motionlib.cli.common import add_animation, animation_arg


def add_info(subparsers) -> None:
    p = subparsers.add_parser("info", help="describe a capture file",
                              description="Print format, frame rate, frames, duration, joints "
                                          "and the detected rest-pose frame of a capture.")
    p.add_argument("file", help="a .bvh or .fbx file, or an .amc file with --asf")
    p.add_argument("--asf", help="the ASF skeleton of an .amc file")
    add_animation(p)
    p.set_defaults(handler=run_info)


def run_info(args) -> int:
    from motionlib.io import read

    animations = []
    if args.file.lower().endswith(".fbx"):
        from motionlib.io.fbx import pick_animation, read_fbx_all

        takes = read_fbx_all(args.file)
        take = pick_animation(takes, animation_arg(args.animation), args.file)
        animations = _animations(take, takes)
    else:
        take = read(args.file, asf=args.asf)
    rest = "none" if take.rest_pose_frame is None else str(take.rest_pose_frame)
    rows = [("file", args.file), ("format", take.format), *animations,
            ("fps", f"{take.fps:g}"),
            ("frames", str(take.n_frames)), ("duration", f"{take.duration:.3f} s"),
            ("joints", str(take.skeleton.n_joints)), ("channels", str(take.skeleton.n_channels)),
            ("rest pose frame", rest), ("body parts", _body_parts(take))]
    for key, value in rows:
        print(f"{key + ':':<17}{value}")
    return 0


def _animations(take, takes) -> list[tuple[str, str]]:
    """For an FBX: the animation shown and, when there are several, all of them."""
    names = [t.animation for t in takes]
    rows = [("animation", take.animation)]
    if len(names) > 1:
        rows.append(("animations", ", ".join(f"{i}: {n}" for i, n in enumerate(names))))
    return rows


def _body_parts(take) -> str:
    """How many canonical body parts the joint names map to (segmenters need them)."""
    from motionlib import markersets
    from motionlib.points import is_point_take
    from motionlib.skeleton import CANONICAL_PARTS, match_parts

    if is_point_take(take):
        if take.marker_set is None:
            return f"not mapped (points of no known marker set: {markersets.KNOWN})"
        try:
            _, joints = markersets.body_joints(take)
        except ValueError as exc:
            return f"not mapped ({exc})"
        return (f"{len(joints)} of {len(CANONICAL_PARTS)} mapped "
                f"({markersets.TITLES[take.marker_set]} points)")
    found, missing = match_parts(take)
    if missing:
        return f"not mapped (no joint found for {', '.join(missing)})"
    return f"{len(found)} of {len(CANONICAL_PARTS)} mapped"


def add_convert(subparsers) -> None:
    p = subparsers.add_parser("convert", help="convert a capture to BVH",
                              description="Write a capture (CMU .amc with --asf, .fbx or .bvh) "
                                          "as BVH; joint positions are unchanged.")
    p.add_argument("input", help="an .amc file (with --asf), an .fbx or a .bvh file")
    p.add_argument("output", help="the .bvh file to write")
    p.add_argument("--asf", help="the ASF skeleton of an .amc input")
    add_animation(p)
    p.add_argument("--start", type=int, help="first frame to keep (0-based)")
    p.add_argument("--stop", type=int, help="frame to stop before (exclusive)")
    p.set_defaults(handler=run_convert)


def run_convert(args) -> int:
    from motionlib.io import read, write_bvh
    from motionlib.take import frame_range

    take = read(args.input, asf=args.asf, animation=animation_arg(args.animation))
    start, stop = frame_range(take.n_frames, args.start, args.stop) if take.n_frames else (0, 0)
    write_bvh(take, args.output, start=start, stop=stop)
    print(f"wrote {args.output}: frames {start} to {stop - 1} of {args.input} "
          f"({stop - start} frames at {take.fps:g} fps)")
    return 0
