"""Studio-length takes for the browser tests and the review playback benchmark: CMU take
13_29 (38 s at 120 fps) repeated to any length, stored the way ingest stores a capture
(positions .npy, signals .npz) with a finished run whose candidates and signals are the
default detector's on 13_29, repeated with it. Built from frames, not a BVH upload: the
text of an hour would be ~240 MB and ingest is not what these measure."""

from functools import cache

import numpy as np

from motionlib.shared_data import data_dir

TAKE_13_29 = data_dir() / "cmu" / "bvh" / "13_29.bvh"


@cache
def take_13_29():
    """(take, positions (n_frames, n_joints, 3) float32, candidate frames, confidences,
    signals {name: (n_frames,) float32}) of 13_29 as read and detected once."""
    import motionlib
    from motionlib.segmenters import get_segmenter

    take = motionlib.read(str(TAKE_13_29))
    segmenter = get_segmenter("default")
    result = segmenter(**segmenter.validate_params({})).fit_predict(take)
    positions = np.asarray(motionlib.forward_kinematics(take), dtype="<f4")
    signals = {k: np.asarray(v, dtype="<f4") for k, v in result.signals.items()}
    return take, positions, np.asarray(result.cuts), np.asarray(result.confidence), signals


def repeated_capture(project, user, seconds, name=None):
    """A ready capture of 13_29's motion repeated for ``seconds`` (cut at a whole frame),
    with a finished run of the default detector's candidates and signals, repeated too."""
    from django.core.files.base import ContentFile

    import motionlib
    from segmentation.files import storage
    from segmentation.models import Capture, DetectionRun

    take, base, cuts, confidence, signals = take_13_29()
    n_frames = int(round(seconds * take.fps))
    repeats = -(-n_frames // take.n_frames)
    capture = Capture(
        project=project, uploaded_by=user, name=name or f"13_29_x{repeats}.bvh", format="bvh",
        checksum=f"13_29-{n_frames}", status="ready", fps=take.fps, n_frames=n_frames,
        n_joints=base.shape[1],
        skeleton={"joints": list(take.skeleton.names), "parents": [int(p) for p in take.skeleton.parents],
                  "height": float(motionlib.skeleton_height(take)), "up": "y"},
    )
    capture.original.save(capture.name, ContentFile(b"built from 13_29's frames, repeated"), save=False)
    storage.save_npy(capture.positions, "positions.npy", np.resize(base, (n_frames, *base.shape[1:])))
    capture.save()
    offsets = np.arange(repeats)[:, None] * take.n_frames
    frames = (offsets + cuts[None, :]).ravel()
    scores = np.tile(confidence, repeats)
    run = DetectionRun(capture=capture, method="default", params={}, status="ready",
                       candidates=[{"frame": int(f), "confidence": round(float(c), 4)}
                                   for f, c in zip(frames, scores, strict=True) if 0 < f < n_frames])
    storage.save_npz(run.signals, "signals.npz", {k: np.resize(v, n_frames) for k, v in signals.items()})
    run.save()
    return capture
