"""`rotomorph simulate` on the example lattice design gives the report's numbers for it."""

from __future__ import annotations

from pathlib import Path

import pytest

from rotomorph.io.designfile import load_design
from rotomorph.materials import FilamentModel
from rotomorph.simulate.design import simulate_design
from rotomorph.simulate.report import LATTICE_STEPS, PATH_CHECK_FACTOR, _heat
from rotomorph.simulate.validation import at_resolution

DOME = Path(__file__).resolve().parents[2] / "examples" / "designs" / "lattice_dome.toml"


@pytest.mark.slow
def test_the_dome_design_simulates_to_the_reports_dome():
    design = load_design(DOME)
    assert design.lattice is not None and design.contact is not None
    assert design.contact.path_check == PATH_CHECK_FACTOR  # the report's path check
    sim = simulate_design(design, steps=LATTICE_STEPS)
    _, res, why = _heat(
        "dome",
        False,
        LATTICE_STEPS,
        at_resolution(FilamentModel()),
        design.lattice.ghost_nodes,
        True,
        path_check=PATH_CHECK_FACTOR,
    )
    assert res is not None, why
    lat = sim.lattice
    # the same multistable lattice, the same kept end state: energy, area and sign agree
    assert lat.path_check is not None and lat.path_check.kept == res.path_check.kept
    assert float(lat.energy[-1]) == pytest.approx(float(res.energy[-1]), rel=1e-9)
    assert lat.final_area_ratio == pytest.approx(res.final_area_ratio, rel=1e-9)
    assert int(lat.gaussian_sign[-1]) == int(res.gaussian_sign[-1]) == 1
