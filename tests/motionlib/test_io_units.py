"""The length unit an export assumes: the file's declared one when the figure is a person in it,
else the first common motion-capture unit that makes it one."""

from dataclasses import replace

import pytest

from motionlib import synth
from motionlib.io.units import length_unit
from motionlib.kinematics import skeleton_height


def take_in(metres_per_unit, format="bvh"):
    """A synthetic CMU-shaped take (1.5 m tall) whose numbers are in ``metres_per_unit``."""
    take = synth.generate(seed=1, fps=30.0, duration=30.0)[0]
    cmu = 0.0254 / 0.45
    k = cmu / metres_per_unit
    skeleton = replace(take.skeleton, offsets=take.skeleton.offsets * k)
    channels = take.channels.copy()
    for names, first in zip(skeleton.channels, skeleton.channel_starts, strict=True):
        for i, name in enumerate(names):
            if name.endswith("position"):
                channels[:, first + i] *= k
    return replace(take, skeleton=skeleton, channels=channels, format=format)


@pytest.mark.parametrize(("metres", "name"), [
    (0.01, "centimetre"), (1.0, "metre"), (0.001, "millimetre"),
    (0.0254 / 0.45, "CMU Acclaim unit (inch / 0.45)"),
])
def test_it_chooses_the_unit_that_makes_a_bvh_figure_a_person(metres, name):
    unit = length_unit(take_in(metres))
    assert (unit.name, unit.declared) == (name, False)
    assert unit.metres == pytest.approx(metres)


def test_it_keeps_an_fbx_takes_declared_centimetres_when_the_figure_is_a_person():
    unit = length_unit(take_in(0.01, format="fbx"))
    assert (unit.name, unit.metres, unit.declared) == ("centimetre", 0.01, True)
    assert unit.describe() == "centimetre (declared by the file)"


def test_it_rescales_an_fbx_whose_declared_metre_held_cmu_units():
    take = take_in((0.0254 / 0.45) / 100, format="fbx")  # a CMU unit written as a metre
    unit = length_unit(take)
    assert unit.declared is False
    assert unit.metres == pytest.approx(0.01 * 0.0254 / 0.45)
    assert 1.3 < skeleton_height(take) * unit.metres < 1.9


def test_it_leaves_a_figure_no_unit_makes_a_person_in_its_declared_unit():
    unit = length_unit(take_in(1e-6, format="fbx"))  # 1.5e6 cm: no unit makes it a person
    assert (unit.name, unit.metres, unit.declared) == ("centimetre", 0.01, True)
