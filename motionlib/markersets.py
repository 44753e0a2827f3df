"""Known marker sets and joint namings of point takes: which points stand for which body part,
and which pairs of points are drawn linked.

Conventions:

- ``plug-in gait``: Vicon's Plug-in Gait full-body markers (``LFHD``, ``C7``, ``LASI``,
  ``LKNE``, ...; the older waist names ``LFWT``/``LBWT`` as in HDM05 are the same markers as
  ``LASI``/``LPSI``, HDM05's shin ``LSHN`` is ``LTIB``). Markers sit on the skin, not at the joint centres, so a body part is
  the mean of the markers around it (the head of the four head markers, the pelvis of the
  four pelvis markers, a hip of its side's front and back pelvis markers, a wrist of its two
  wrist-bar markers) or the marker on it (shoulder, elbow, knee, ankle, toe). That is a few
  centimetres from the anatomical joint centre, the same offset in every frame, which is
  all that angles between limbs and changes of pose need.
- ``kinect v1`` (Kinect SDK 1 / UTKinect: ``hip_center``, ``shoulder_center``,
  ``elbow_left``, ...) and ``kinect v2`` (``spine_base``, ``spine_shoulder``, ``neck``, ...):
  tracked joints, one per part.

Names are compared after dropping a subject prefix (``Bastian:LFHD`` -> ``LFHD``),
lower-casing and removing spaces, ``_`` and ``-``. A set of points that follows none of them
is still a take: its points are drawn unlinked, and the methods that need body parts say so.
"""

from __future__ import annotations

import numpy as np

from motionlib.errors import CaptureError
from motionlib.gaps import filled
from motionlib.skeleton import CANONICAL_PARTS, OPTIONAL_PARTS


def normalise(name: str) -> str:
    plain = name.rsplit(":", 1)[-1].lower()
    for ch in " _-":
        plain = plain.replace(ch, "")
    return PIG_ALIASES.get(plain, plain)


PIG_ALIASES = {"lfwt": "lasi", "rfwt": "rasi", "lbwt": "lpsi", "rbwt": "rpsi", "rbac": "rbak",
               "lshn": "ltib", "rshn": "rtib"}


def _sided(left: dict[str, list[str]], mirror) -> dict[str, list[str]]:
    table = dict(left)
    for part, names in left.items():
        if part.startswith("left_"):
            table["right_" + part[5:]] = [mirror(n) for n in names]
    return table


def _pig_mirror(name: str) -> str:
    return "r" + name[1:]


def _kinect_mirror(name: str) -> str:
    return name.replace("left", "right")


# Part -> the points averaged for it (those present in the take).
PARTS: dict[str, dict[str, list[str]]] = {
    "plug-in gait": _sided({
        "root": ["lasi", "rasi", "lpsi", "rpsi"], "spine": ["t10", "strn"],
        "chest": ["c7", "clav", "t10", "strn"], "neck": ["c7", "clav"],
        "head": ["lfhd", "rfhd", "lbhd", "rbhd"], "left_shoulder": ["lsho"],
        "left_elbow": ["lelb"], "left_wrist": ["lwra", "lwrb"], "left_hip": ["lasi", "lpsi"],
        "left_knee": ["lkne"], "left_ankle": ["lank"], "left_toe": ["ltoe"],
    }, _pig_mirror),
    "kinect v1": _sided({
        "root": ["hipcenter"], "spine": ["spine"], "chest": ["shouldercenter"],
        "neck": ["shouldercenter"], "head": ["head"], "left_shoulder": ["shoulderleft"],
        "left_elbow": ["elbowleft"], "left_wrist": ["wristleft"], "left_hip": ["hipleft"],
        "left_knee": ["kneeleft"], "left_ankle": ["ankleleft"], "left_toe": ["footleft"],
    }, _kinect_mirror),
    "kinect v2": _sided({
        "root": ["spinebase"], "spine": ["spinemid"], "chest": ["spineshoulder"],
        "neck": ["neck"], "head": ["head"], "left_shoulder": ["shoulderleft"],
        "left_elbow": ["elbowleft"], "left_wrist": ["wristleft"], "left_hip": ["hipleft"],
        "left_knee": ["kneeleft"], "left_ankle": ["ankleleft"], "left_toe": ["footleft"],
    }, _kinect_mirror),
}


def _links(left: dict[str, str], centre: dict[str, str], mirror) -> dict[str, str]:
    """``centre`` links plus ``left`` ones and their mirror images (a left parent mirrored)."""
    table = dict(centre)
    left_points = set(left) | {"lasi", "lpsi"}
    for child, parent in left.items():
        table[child] = parent
        table[mirror(child)] = mirror(parent) if parent in left_points else parent
    return table


# Point -> the point it is drawn linked to (a forest). A known marker set is one tree: for
# Plug-in Gait it hangs from LASI, the trunk rises from the back of the pelvis (LPSI, T10,
# C7), crosses at the neck to the front (CLAV, STRN); a wand marker (UPA in the upper third
# of the upper arm, FRM, THI, TIB in the lower third of theirs) hangs from the joint marker
# nearest it, RBAK (on the right shoulder blade) from C7.
LINKS: dict[str, dict[str, str]] = {
    "plug-in gait": _links(
        {"lsho": "clav", "lupa": "lsho", "lelb": "lsho", "lfrm": "lwra", "lwra": "lelb",
         "lwrb": "lwra", "lfin": "lwra", "lkne": "lasi", "lthi": "lkne", "ltib": "lank",
         "lank": "lkne", "lhee": "lank", "ltoe": "lank", "lmt5": "ltoe", "lfhd": "c7",
         "lbhd": "lfhd"},
        {"rasi": "lasi", "lpsi": "lasi", "rpsi": "lpsi", "t10": "lpsi", "c7": "t10",
         "clav": "c7", "strn": "clav", "rbak": "c7"},
        _pig_mirror),
    "kinect v1": _links(
        {"shoulderleft": "shouldercenter", "elbowleft": "shoulderleft",
         "wristleft": "elbowleft", "handleft": "wristleft", "hipleft": "hipcenter",
         "kneeleft": "hipleft", "ankleleft": "kneeleft", "footleft": "ankleleft"},
        {"spine": "hipcenter", "shouldercenter": "spine", "head": "shouldercenter"},
        _kinect_mirror),
    "kinect v2": _links(
        {"shoulderleft": "spineshoulder", "elbowleft": "shoulderleft",
         "wristleft": "elbowleft", "handleft": "wristleft", "handtipleft": "handleft",
         "thumbleft": "handleft", "hipleft": "spinebase", "kneeleft": "hipleft",
         "ankleleft": "kneeleft", "footleft": "ankleleft"},
        {"spinemid": "spinebase", "spineshoulder": "spinemid", "neck": "spineshoulder",
         "head": "neck"},
        _kinect_mirror),
}

TITLES = {"plug-in gait": "Plug-in Gait", "kinect v1": "Kinect v1", "kinect v2": "Kinect v2"}
KNOWN = ", ".join(TITLES.values())


def _required(table: dict[str, list[str]]) -> list[str]:
    return [p for p in CANONICAL_PARTS if p not in OPTIONAL_PARTS and p in table]


def identify(names: list[str]) -> str | None:
    """The convention whose required body parts all have a point among ``names``, else None
    (the one covering the most points when several do)."""
    present = {normalise(n) for n in names}
    best, best_count = None, 0
    for convention, table in PARTS.items():
        if all(present & set(table[p]) for p in _required(table)):
            count = len(present & {m for ms in table.values() for m in ms})
            if count > best_count:
                best, best_count = convention, count
    return best


def link_parents(names: list[str], convention: str | None) -> list[int]:
    """For each point, the index of the point it is drawn linked to (-1: none)."""
    if convention is None:
        return [-1] * len(names)
    index = {}
    for i, name in enumerate(names):
        index.setdefault(normalise(name), i)
    links = LINKS[convention]
    return [index.get(links.get(normalise(n), ""), -1) for n in names]


def body_joints(take) -> tuple[np.ndarray, dict[str, int]]:
    """Canonical body parts of a point take, for the segmenters' features.

    Each part is the mean of its points (``PARTS``) over the points seen at least once, after
    the gaps of each point are closed (``gaps.filled``; features only).

    Returns
    -------
    positions : (n_frames, n_parts, 3) float64, Y up, the take's unit, no NaN.
    joints : part -> index into ``positions``, in ``CANONICAL_PARTS`` order.

    Raises
    ------
    CaptureError
        The points follow no known convention, or no point of a required part was seen.
    """
    if take.marker_set is None:
        raise CaptureError(f"the points ({', '.join(take.point_names[:12])}"
                           f"{', ...' if take.n_points > 12 else ''}) follow no known marker "
                           f"set ({KNOWN}), so no body parts are known", path=take.path)
    return body_parts(take.point_names, take.positions, take.marker_set, path=take.path)


def body_parts(names: list[str], positions: np.ndarray, convention: str,
               path=None) -> tuple[np.ndarray, dict[str, int]]:
    """:func:`body_joints` from point names, their positions ``(n_frames, n_points, 3)``
    (NaN at gaps) and the convention they follow."""
    table = PARTS[convention]
    points = filled(positions)
    seen = ~np.isnan(points[0, :, 0])
    index = {}
    for i, name in enumerate(names):
        if seen[i]:
            index.setdefault(normalise(name), i)
    parts, joints = [], {}
    for part in CANONICAL_PARTS:
        members = [index[m] for m in table.get(part, []) if m in index]
        if not members:
            if part in OPTIONAL_PARTS:
                continue
            raise CaptureError(f"no point of the {part.replace('_', ' ')} "
                               f"({', '.join(m.upper() for m in table[part])}) is seen in "
                               f"any frame", path=path)
        joints[part] = len(parts)
        parts.append(points[:, members].mean(axis=1))
    return np.stack(parts, axis=1), joints
