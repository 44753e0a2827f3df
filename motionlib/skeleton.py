"""Joint trees, their channel layout, and the map from joint names to canonical body parts.

A :class:`Skeleton` is BVH-shaped whatever the file format: joints in depth-first order (a parent
always precedes its children), each located at the point it rotates about, with an offset from
its parent in the parent's frame and its own channels. CMU ASF bones are converted to this shape
by :mod:`motionlib.io.asf_amc` (the ``axes`` field carries the ASF ``axis`` frames).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from motionlib.errors import CaptureError, InputError

POSITION_CHANNELS = ("Xposition", "Yposition", "Zposition")
ROTATION_CHANNELS = ("Xrotation", "Yrotation", "Zrotation")
CHANNEL_NAMES = POSITION_CHANNELS + ROTATION_CHANNELS

CANONICAL_PARTS = (
    "root", "spine", "chest", "neck", "head",
    "left_shoulder", "left_elbow", "left_wrist",
    "right_shoulder", "right_elbow", "right_wrist",
    "left_hip", "left_knee", "left_ankle", "left_toe",
    "right_hip", "right_knee", "right_ankle", "right_toe",
)
# Toes are mapped when the skeleton has them; every other part is required.
OPTIONAL_PARTS = frozenset({"left_toe", "right_toe"})


@dataclass(eq=False)
class Skeleton:
    """A joint tree with its channel layout.

    Attributes
    ----------
    names : list of str
        Joint names, depth-first (parents before children).
    parents : ndarray of int, shape (n_joints,)
        Index of each joint's parent, -1 for the root.
    offsets : ndarray of float, shape (n_joints, 3)
        Joint position relative to its parent, in the parent's frame, file length unit.
    channels : list of tuple of str
        Per joint, its channel names in data order (``"Xposition"`` … ``"Zrotation"``).
    rotation_orders : list of str
        Per joint, the order in which its rotations compose, left to right: ``"ZYX"`` means
        ``R = Rz @ Ry @ Rx``. For BVH this is the order the rotation channels are listed in.
    axes : ndarray of float, shape (n_joints, 3, 3), optional
        ASF ``axis`` frames ``C``: the joint's local rotation is ``C @ R @ C.T``. None for BVH.
    end_sites : dict of int to ndarray of shape (3,)
        End Site offsets keyed by the index of the joint that carries them.
    point_set : bool
        True for the points of a marker or joint-position take (``motionlib.points``): no
        channels, and parents are the links drawn between points, a forest in any order.
    """

    names: list[str]
    parents: np.ndarray
    offsets: np.ndarray
    channels: list[tuple[str, ...]]
    rotation_orders: list[str]
    axes: np.ndarray | None = None
    end_sites: dict[int, np.ndarray] = field(default_factory=dict)
    point_set: bool = False

    def __post_init__(self):
        self.parents = np.asarray(self.parents, dtype=np.intp)
        self.offsets = np.asarray(self.offsets, dtype=np.float64).reshape(-1, 3)
        n = len(self.names)
        if not (len(self.parents) == len(self.offsets) == len(self.channels)
                == len(self.rotation_orders) == n):
            raise InputError("names, parents, offsets, channels and rotation_orders "
                             f"must all have one entry per joint ({n})")
        if self.point_set:
            # A set of points (motionlib.points): parents are only the links drawn between
            # them, a forest in any order.
            if not _is_forest(self.parents):
                raise InputError("point links must form a forest: each parent -1 or another "
                                 "point, without cycles")
        elif n and not _is_preorder(self.parents):
            raise InputError("joints must be in depth-first order (as BVH nests them): root "
                             "first, each joint right after its parent or a sibling's subtree")

    @property
    def n_joints(self) -> int:
        return len(self.names)

    @property
    def n_channels(self) -> int:
        return sum(len(c) for c in self.channels)

    @property
    def channel_starts(self) -> np.ndarray:
        """Column of each joint's first channel in ``Take.channels``, shape (n_joints,)."""
        counts = [len(c) for c in self.channels]
        return np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.intp)

    def index(self, name: str) -> int:
        """Index of the joint called ``name``; ``KeyError`` naming it when absent."""
        try:
            return self.names.index(name)
        except ValueError:
            raise KeyError(f"no joint named {name!r}") from None

    def children(self, j: int) -> list[int]:
        return [int(c) for c in np.flatnonzero(self.parents == j)]

    def children_lists(self) -> list[list[int]]:
        """Every joint's children in order, in one pass: ``children_lists()[j] == children(j)``."""
        lists: list[list[int]] = [[] for _ in self.names]
        for j, p in enumerate(self.parents.tolist()):
            if p >= 0:
                lists[p].append(j)
        return lists


def _is_forest(parents: np.ndarray) -> bool:
    """True if every parent is -1 or another joint and following parents always ends."""
    n = len(parents)
    if ((parents < -1) | (parents >= n) | (parents == np.arange(n))).any():
        return False
    for j in range(n):
        k, steps = j, 0
        while parents[k] >= 0 and steps <= n:
            k, steps = parents[k], steps + 1
        if steps > n:
            return False
    return True


def _is_preorder(parents: np.ndarray) -> bool:
    """True if joint j's parent is joint j-1 or one of its ancestors, for every j > 0."""
    if parents[0] != -1:
        return False
    chain = [0]  # ancestors of the previous joint, itself last
    for j in range(1, len(parents)):
        while chain and chain[-1] != parents[j]:
            chain.pop()
        if not chain:
            return False
        chain.append(j)
    return True


# Candidate joint names per canonical part, per naming convention; compared after lower-casing
# and dropping a namespace prefix ("mixamorig:Hips" -> "hips"), and also without a character
# prefix ("Character1_Hips" -> "hips", "DEF-thigh.L" -> "thigh.l"). The first present name wins.
def _sided(left: dict[str, list[str]]) -> dict[str, list[str]]:
    table = dict(left)
    for part, names in left.items():
        if part.startswith("left_"):
            table["right_" + part[5:]] = [_mirror(n) for n in names]
    return table


def _mirror(name: str) -> str:
    for a, b in ((".l", ".r"), ("_l", "_r")):  # Blender's side suffixes
        if name.endswith(a):
            return name[: -len(a)] + b
    for a, b in (("left", "right"), ("l", "r")):
        if name.startswith(a):
            return b + name[len(a):]
    raise AssertionError(name)


CONVENTIONS: dict[str, dict[str, list[str]]] = {
    # Mixamo: Spine just above the hips, Spine2 at the chest.
    "mixamo": _sided({
        "root": ["hips"], "spine": ["spine1"], "chest": ["spine2"], "neck": ["neck"],
        "head": ["head"], "left_shoulder": ["leftarm"], "left_elbow": ["leftforearm"],
        "left_wrist": ["lefthand"], "left_hip": ["leftupleg"], "left_knee": ["leftleg"],
        "left_ankle": ["leftfoot"], "left_toe": ["lefttoebase", "lefttoe_end"],
    }),
    # cgspeed's CMU conversion: Hips, LowerBack, Spine (= upperback), Spine1 (= thorax), ...
    "cgspeed": _sided({
        "root": ["hips"], "spine": ["spine"], "chest": ["spine1"], "neck": ["neck"],
        "head": ["head"], "left_shoulder": ["leftarm"], "left_elbow": ["leftforearm"],
        "left_wrist": ["lefthand"], "left_hip": ["leftupleg"], "left_knee": ["leftleg"],
        "left_ankle": ["leftfoot"], "left_toe": ["lefttoebase"],
    }),
    # DAZ / Poser (and cgspeed's "Daz-friendly" CMU conversion).
    "daz": _sided({
        "root": ["hip", "hips"], "spine": ["abdomen", "abdomenupper", "abdomenlower"],
        "chest": ["chest", "chestupper", "chestlower"], "neck": ["neck", "necklower"],
        "head": ["head"], "left_shoulder": ["lshldr", "lshldrbend"],
        "left_elbow": ["lforearm", "lforearmbend"], "left_wrist": ["lhand"],
        "left_hip": ["lthigh", "lthighbend"], "left_knee": ["lshin"], "left_ankle": ["lfoot"],
        "left_toe": ["ltoe", "lmetatarsals"],
    }),
    # MotionBuilder HumanIK (Mixamo's ancestor), usually under a character prefix
    # ("Character1_Hips", dropped before matching); the chest is Spine2, or Spine1 when the
    # spine has two bones.
    "humanik": _sided({
        "root": ["hips"], "spine": ["spine"], "chest": ["spine2", "spine1"], "neck": ["neck"],
        "head": ["head"], "left_shoulder": ["leftarm"], "left_elbow": ["leftforearm"],
        "left_wrist": ["lefthand"], "left_hip": ["leftupleg"], "left_knee": ["leftleg"],
        "left_ankle": ["leftfoot"], "left_toe": ["lefttoebase"],
    }),
    # Blender's own naming (the Human meta-rig, Rigify's deform bones without "DEF-", and the
    # ".L"/"_L" side suffixes).
    "blender": _sided({
        "root": ["spine", "hips", "pelvis"], "spine": ["spine.001"],
        "chest": ["spine.003", "spine.002", "chest"], "neck": ["spine.004", "neck"],
        "head": ["spine.006", "head"], "left_shoulder": ["upper_arm.l", "upperarm.l",
                                                         "upper_arm_l"],
        "left_elbow": ["forearm.l", "lower_arm.l", "forearm_l"],
        "left_wrist": ["hand.l", "hand_l"], "left_hip": ["thigh.l", "upper_leg.l", "thigh_l"],
        "left_knee": ["shin.l", "lower_leg.l", "calf.l", "shin_l"],
        "left_ankle": ["foot.l", "foot_l"], "left_toe": ["toe.l", "toes.l", "toe_l"],
    }),
    # CMU ASF bone names; a joint sits where its bone starts.
    "cmu": _sided({
        "root": ["root"], "spine": ["upperback"], "chest": ["thorax"], "neck": ["lowerneck"],
        "head": ["head"], "left_shoulder": ["lhumerus"], "left_elbow": ["lradius"],
        "left_wrist": ["lwrist"], "left_hip": ["lfemur"], "left_knee": ["ltibia"],
        "left_ankle": ["lfoot"], "left_toe": ["ltoes"],
    }),
}


def _plain(name: str) -> str:
    return name.rsplit(":", 1)[-1].strip().lower()


def _unprefixed(plain: str) -> str | None:
    for separator in ("-", "_"):
        head, sep, rest = plain.partition(separator)
        if sep and rest and head not in ("upper", "lower", "left", "right"):
            return rest
    return None


def _match(names: list[str], table: dict[str, list[str]]) -> dict[str, int]:
    lookup = {}
    for i, name in enumerate(names):
        lookup.setdefault(_plain(name), i)
    for i, name in enumerate(names):
        bare = _unprefixed(_plain(name))
        if bare:
            lookup.setdefault(bare, i)
    found = {}
    for part, candidates in table.items():
        hit = next((lookup[c] for c in candidates if c in lookup), None)
        if hit is not None:
            found[part] = hit
    return found


def _skeleton_of(take_or_skeleton) -> Skeleton:
    return getattr(take_or_skeleton, "skeleton", take_or_skeleton)


def canonical_indices(take) -> dict[str, int]:
    """Map canonical body parts to joint indices.

    Parameters
    ----------
    take : Take or Skeleton

    Returns
    -------
    dict of str to int
        ``{part: joint index}`` for every part in :data:`CANONICAL_PARTS` (toes only when the
        skeleton has toe joints). ``left_hip`` is where the left thigh rotates, and so on.

    Raises
    ------
    CaptureError
        If no known naming convention (CMU ASF, cgspeed BVH, DAZ, Mixamo, MotionBuilder
        HumanIK, Blender) covers the skeleton;
        the message lists the parts that could not be found.
    """
    found, missing = match_parts(take)
    if missing:
        names = _skeleton_of(take).names
        raise CaptureError(
            "cannot map the skeleton to body parts (known namings: CMU ASF, cgspeed BVH, DAZ, "
            f"Mixamo, MotionBuilder HumanIK, Blender); no joint found for {', '.join(missing)}; joints are "
            f"{', '.join(names[:40])}",
            path=getattr(take, "path", None))
    return found


def match_parts(take) -> tuple[dict[str, int], list[str]]:
    """The best mapping any known naming gives, and the required parts it leaves unmapped.

    Returns
    -------
    found : dict of str to int
        ``{part: joint index}`` in :data:`CANONICAL_PARTS` order.
    missing : list of str
        Required parts (all but the toes) without a joint.
    """
    skeleton = _skeleton_of(take)
    best: dict[str, int] = {}
    for table in CONVENTIONS.values():
        found = _match(skeleton.names, table)
        if len(found) > len(best):
            best = found
    missing = [p for p in CANONICAL_PARTS if p not in best and p not in OPTIONAL_PARTS]
    return {p: best[p] for p in CANONICAL_PARTS if p in best}, missing


def canonical_joints(take) -> dict[str, str]:
    """Map joint names to canonical body parts: ``{take joint name: part}``.

    See :func:`canonical_indices` for the parts and the errors.
    """
    skeleton = _skeleton_of(take)
    return {skeleton.names[j]: part for part, j in canonical_indices(take).items()}
