"""Printed filaments (print program -> natural field -> rod) converge fast at every rotation
rate and temperature; regression for rigid modes that ignored the frames' twist."""

from __future__ import annotations

import pytest

from rotomorph.design.path import Line, Path
from rotomorph.design.program import PrintProgram
from rotomorph.materials.natural import natural_field
from rotomorph.rod.model import Model
from rotomorph.solve.static import solve_static


@pytest.mark.parametrize("rotation", [0.6, 10.0, 20.0])  # rad/s at 3 mm/s: w* = 0.06, 1, 2
@pytest.mark.parametrize("temperature", [25.0, 60.0, 175.0])
def test_printed_filament_converges_quickly(rotation, temperature):
    path = Path.from_segments([Line(30.0)], spacing=0.3)
    program = PrintProgram.from_rotation(path, speed=3.0, rotation=rotation)
    field = natural_field(program, temperature=temperature)
    model = Model.chain(
        program.points,
        bending_stiffness1=field.bending_stiffness1,
        bending_stiffness2=field.bending_stiffness2,
        twist_stiffness=field.twist_stiffness,
        axial_stiffness=field.axial_stiffness,
        directors=field.directors,
        natural_curvature1=field.curvature1,
        natural_curvature2=field.curvature2,
        natural_twist=field.twist,
        rest_length=field.rest_length,
    )
    res = solve_static(model)
    assert res.iterations <= 20
    assert res.residual <= 1e-8
