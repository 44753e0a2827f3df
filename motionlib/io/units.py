"""The length unit of a take, in metres, so that exported clips come out human-sized.

BVH and ASF/AMC files declare no length unit that tools agree on, and an FBX declares one that
its maker may not have meant (a CMU BVH imported into Blender at scale 1 and written as FBX
declares a 27 m figure). What a clip's length unit is, is decided here, once for every export:

1. the unit the file declares (FBX: centimetres, as :mod:`motionlib.io.fbx` reads it), when the
   figure is human-sized in it (:data:`HUMAN_HEIGHTS`, head to toe at rest);
2. otherwise the first of the common motion-capture units (:data:`CONVENTIONS`, in that order)
   in which it is, applied to the file's numbers (for an FBX, to the metres it declares);
3. otherwise the declared unit (or metres), unchanged: the figure is no human.

The choice is named in every export's manifest; docs/exports.md lists the rules.
"""

from __future__ import annotations

from dataclasses import dataclass

from motionlib.kinematics import skeleton_height
from motionlib.take import Take

# Head-to-toe heights, in metres, taken as a person's: a small child to a tall adult.
HUMAN_HEIGHTS = (0.5, 2.5)
INCH = 0.0254
# (name, metres per unit), tried in this order. CMU's ASF/AMC files (and cgspeed's BVH made from
# them) are in Acclaim units of `length 0.45`: inches divided by 0.45.
CONVENTIONS = (
    ("centimetre", 0.01),
    ("metre", 1.0),
    ("CMU Acclaim unit (inch / 0.45)", INCH / 0.45),
    ("millimetre", 0.001),
    ("inch", INCH),
)
# What a reader's numbers are, where the format declares it.
DECLARED = {"fbx": ("centimetre", 0.01)}


@dataclass(frozen=True)
class LengthUnit:
    """A take's length unit: ``metres`` per unit of its numbers, ``name``, and whether the file
    declared it (else it was chosen by the figure's height)."""

    name: str
    metres: float
    declared: bool

    def describe(self) -> str:
        how = "declared by the file" if self.declared else "chosen by the figure's height"
        return f"{self.name} ({how})"


def length_unit(take: Take) -> LengthUnit:
    """The take's length unit (see the module docstring)."""
    height = skeleton_height(take)
    name, metres = DECLARED.get(take.format, (None, 1.0))
    if name is not None and _human(height * metres):
        return LengthUnit(name, metres, True)
    for convention, factor in CONVENTIONS:
        if _human(height * metres * factor):
            # For an FBX, its declared metre held something else; say what.
            label = convention if name is None else f"{convention} written as metres"
            return LengthUnit(label, metres * factor, False)
    return LengthUnit(name or "metre", metres, name is not None)


def _human(metres: float) -> bool:
    return HUMAN_HEIGHTS[0] <= metres <= HUMAN_HEIGHTS[1]
