"""A nuisance sample's lattice: its geometry, inks and buoyant weight are the sample's."""

from __future__ import annotations

import dataclasses

import pytest

from rotomorph.materials.material import get_material
from rotomorph.simulate.nuisance import latin_hypercube, nominal_sample
from rotomorph.simulate.nuisance_lattices import (
    BATH_EXPANSION,
    buoyant_density,
    sample_buoyancy,
    sample_lattice,
    transition_material,
)


def test_the_lattice_of_a_sample_has_its_cell_width_and_transition() -> None:
    s = latin_hypercube(4, seed=1)[2]
    lat = sample_lattice("contracting", 2, 2, s)
    assert lat.spacing == pytest.approx(s.cell_size)
    assert lat.amplitude == pytest.approx(0.25 * s.cell_size)
    assert lat.radius == pytest.approx(0.5 * s.filament_width)
    active = get_material(lat.active_material)
    assert active.transition_temperature == pytest.approx(s.transition)
    # everything else about the ink is the paper's
    base = get_material("lce")
    assert dataclasses.replace(active, name="lce", transition_temperature=0.0) == (
        dataclasses.replace(base, transition_temperature=0.0)
    )
    assert transition_material(s.transition) == lat.active_material  # registered once
    assert sample_lattice("contracting", 2, 2).spacing == pytest.approx(nominal_sample().cell_size)


def test_the_buoyant_weight_follows_the_sample_densities_and_the_expanding_bath() -> None:
    s = dataclasses.replace(nominal_sample(), filament_density=1.2, bath_density=0.97)
    lat = sample_lattice("expanding", 2, 2, s)
    g25, g175 = sample_buoyancy(lat, s)(25.0), sample_buoyancy(lat, s)(175.0)
    assert g25.density == 1.2 and g25.fluid_density == pytest.approx(0.97)
    assert g175.fluid_density == pytest.approx(0.97 / (1 + 150 * BATH_EXPANSION))
    assert buoyant_density(s, 175.0) == pytest.approx(1.2 - g175.fluid_density)
