"""Designs that cannot be printed are refused: a filament much wider (or much thinner) than
the nozzle it comes out of, in one line with the fix."""

from __future__ import annotations

import re

import pytest

from rotomorph.errors import InvalidDesignError
from rotomorph.io.design_limits import FILAMENT_PER_NOZZLE, nozzle_for
from rotomorph.io.designfile import parse_design


def _design(radius, diameter=None, lattice=False):
    data = {"schema_version": 1}
    if diameter is not None:
        data["nozzle"] = {"diameter": diameter}
    if lattice:
        data["lattice"] = {"n": 2, "ghost_nodes": 2, "layers": 1, "radius": radius}
    else:
        data["filaments"] = [
            {"radius": radius, "spacing": 0.5, "segments": [{"kind": "line", "length": 60.0}]}
        ]
    return data


@pytest.mark.parametrize(
    ("radius", "diameter", "where"),
    [(5.0, 0.1, "filaments[0].radius"), (0.01, 1.0, "filaments[0].radius")],
)
def test_a_filament_the_nozzle_cannot_print_is_refused(radius, diameter, where):
    with pytest.raises(InvalidDesignError, match=re.escape(where)):
        parse_design(_design(radius, diameter))
    with pytest.raises(InvalidDesignError, match=r"set nozzle\.diameter = ") as info:
        parse_design(_design(radius, diameter))
    assert "\n" not in str(info.value)
    parse_design(_design(radius, nozzle_for(radius)))  # the suggested nozzle fits


def test_the_paper_s_pairs_and_the_band_edges_are_accepted():
    parse_design(_design(0.3, 1.0))  # 0.6 mm filaments from the 1 mm nozzle
    parse_design(_design(0.15, 0.5))  # 0.3 mm from 0.5 mm
    lo, hi = FILAMENT_PER_NOZZLE
    parse_design(_design(lo / 2, 1.0))
    parse_design(_design(hi / 2, 1.0))


def test_lattices_are_checked_too():
    with pytest.raises(InvalidDesignError, match=r"lattice\.radius = 0\.04 mm"):
        parse_design(_design(0.04, 1.0, lattice=True))
