"""The buoyant weight of a lattice follows the bath's density along a temperature ramp."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice import heat_lattice
from rotomorph.lattice.heating import lattice_buoyancy, lattice_gravity
from rotomorph.materials.bath import bath_density


def _lattice():
    return sinusoidal_lattice(3, 5.0, 1.25, 4, "contracting")


def test_buoyancy_is_the_bath_density_at_the_temperature():
    lat = _lattice()
    weight = lattice_buoyancy(lat)
    assert weight(25.0) == lattice_gravity(lat)
    hot = weight(175.0)
    assert hot.fluid_density == pytest.approx(bath_density("silicone_oil", 175.0))
    # the oil expands on heating: the lattice weighs more in the hot bath
    assert hot.line_weight(1)[0] > 1.5 * weight(25.0).line_weight(1)[0]
    with pytest.raises(InvalidParameterError, match="unknown fluid"):
        lattice_buoyancy(lat, bath="water?")


def test_the_ramp_calls_the_weight_at_every_ramp_temperature():
    lat = _lattice()
    seen: list[float] = []
    constant = lattice_gravity(lat)

    def weight(temperature: float):  # type: ignore[no-untyped-def]
        seen.append(float(temperature))
        return constant

    res = heat_lattice(lat, steps=2, floor=True, gravity=weight, branch="continuous")
    same = heat_lattice(lat, steps=2, floor=True, gravity=constant, branch="continuous")
    assert set(np.round(res.parameter[1:], 9)) <= set(np.round(seen, 9))
    np.testing.assert_allclose(res.positions, same.positions, atol=1e-12)
    heavier = heat_lattice(lat, steps=2, floor=True, gravity=lattice_buoyancy(lat),
                           branch="continuous")  # fmt: skip
    assert heavier.energy[-1] != pytest.approx(same.energy[-1], rel=1e-9)
