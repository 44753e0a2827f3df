"""The ``python -m motionlib segment`` command: a method's cuts, or the learner's cuts after
``--examples``."""

from __future__ import annotations

import json


def add_segment(subparsers) -> None:
    p = subparsers.add_parser(
        "segment", help="propose cuts for a capture",
        description="Run a segmentation method on a capture and print its candidate cuts "
                    "(0-based frames) with their confidence.",
    )
    p.add_argument("file", help="a .bvh or .fbx file, or an .amc file with --asf")
    p.add_argument("--asf", help="the ASF skeleton of an .amc file")
    p.add_argument("--animation", help="which animation of an FBX file (name or number; "
                                       "default: the first)")
    p.add_argument("--method", default="default", help="segmentation method (default: default)")
    p.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                   help="method parameter, repeatable")
    p.add_argument("--json", action="store_true", help="print JSON instead of a table")
    p.add_argument("--plot", metavar="OUT.png", help="also draw the signal with the cuts")
    p.add_argument("--examples", metavar="EXAMPLES.csv",
                   help="adapt the default method to these example takes with human cuts "
                        "first (CSV header file,asf,cuts; cuts are 0-based frames separated "
                        "by spaces)")
    p.set_defaults(handler=run_segment)


def run_segment(args) -> int:
    from motionlib.cli.common import animation_arg
    from motionlib.io import read
    from motionlib.segmenters import ParamError, get_segmenter, parse_param_args

    cls = get_segmenter(args.method)
    params = cls.validate_params(parse_param_args(args.param))  # before the slow read
    if args.plot:  # before the slow read too
        from motionlib.cli.plot import require_matplotlib

        require_matplotlib()
    if args.examples and cls.name != "default":
        raise ParamError(f"--examples: only the default method adapts, not {cls.name!r}")
    model = None
    if args.examples:
        from motionlib.adapt import fit_cut_model, read_examples

        model = fit_cut_model(read_examples(args.examples))
    take = read(args.file, asf=args.asf, animation=animation_arg(args.animation))
    if model is not None:
        from motionlib.adapt import detect

        result = detect(take, model, **parse_param_args(args.param))
    else:
        result = cls(**params).fit_predict(take)
    if args.plot:
        from motionlib.cli.plot import plot_segmentation

        plot_segmentation(result, fps=take.fps, path=args.plot,
                          title=f"{args.file} ({cls.name})")
    cuts = [{"frame": int(c), "confidence": round(float(p), 4)}
            for c, p in zip(result.cuts, result.confidence, strict=True)]
    if args.json:
        out = {"fps": take.fps, "n_frames": take.n_frames, "method": cls.name, "cuts": cuts}
        if model is not None:
            out["adapted_from"] = {"takes": model.n_takes, "cuts": model.n_cuts}
        print(json.dumps(out))
        return 0
    adapted = "" if model is None else (
        f", adapted from {model.n_takes} example take{'s' * (model.n_takes != 1)} with "
        f"{model.n_cuts} cut{'s' * (model.n_cuts != 1)}")
    print(f"{args.file}: {len(cuts)} cuts by {cls.name} "
          f"({take.n_frames} frames at {take.fps:g} fps{adapted})")
    print(f"{'frame':>8} {'time s':>9} {'confidence':>10}")
    for cut in cuts:
        print(f"{cut['frame']:>8} {cut['frame'] / take.fps:>9.3f} {cut['confidence']:>10.3f}")
    return 0
