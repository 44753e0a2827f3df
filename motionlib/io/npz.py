"""A take saved whole as ``.npz`` (skeleton, channels, timing): how a converted FBX is kept.

Converting an FBX needs Blender; once done, the take is stored in this form beside the original
so that ingest, detection and exports read it back in milliseconds, without Blender, exactly.
"""

from __future__ import annotations

import io
import json

import numpy as np

from motionlib.errors import CaptureError
from motionlib.skeleton import Skeleton
from motionlib.take import Take

VERSION = 1


def save_take(take: Take, file) -> None:
    """Write ``take`` to ``file`` (a path or a binary file object)."""
    sk = take.skeleton
    meta = {
        "version": VERSION, "name": take.name, "format": take.format, "fps": take.fps,
        "frame_time": take.frame_time, "rest_pose_frame": take.rest_pose_frame,
        "animation": take.animation, "names": sk.names,
        "channels": [list(c) for c in sk.channels], "rotation_orders": sk.rotation_orders,
        "end_sites": {str(j): list(map(float, o)) for j, o in sk.end_sites.items()},
    }
    arrays = {"channels": take.channels, "parents": sk.parents, "offsets": sk.offsets,
              "meta": np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)}
    if sk.axes is not None:
        arrays["axes"] = sk.axes
    np.savez(file, **arrays)


def load_take(file, *, path=None) -> Take:
    """Read a take written by :func:`save_take`; CaptureError if it is not one."""
    try:
        with np.load(file, allow_pickle=False) as data:
            meta = json.loads(bytes(data["meta"]).decode())
            arrays = {k: data[k] for k in data.files if k != "meta"}
    except (OSError, ValueError, KeyError) as exc:
        raise CaptureError(f"not a saved take ({exc})", path=path) from None
    skeleton = Skeleton(
        names=meta["names"], parents=arrays["parents"], offsets=arrays["offsets"],
        channels=[tuple(c) for c in meta["channels"]], rotation_orders=meta["rotation_orders"],
        axes=arrays.get("axes"),
        end_sites={int(j): np.array(o) for j, o in meta["end_sites"].items()})
    return Take(name=meta["name"], format=meta["format"], fps=meta["fps"],
                frame_time=meta["frame_time"], channels=arrays["channels"], skeleton=skeleton,
                rest_pose_frame=meta["rest_pose_frame"], path=path, animation=meta["animation"])


def take_bytes(take: Take) -> bytes:
    buffer = io.BytesIO()
    save_take(take, buffer)
    return buffer.getvalue()
