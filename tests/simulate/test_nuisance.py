"""The nuisance priors: stated ranges, the cell-size relation and the Latin hypercube."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.analysis.aperture import passing_diameters
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.simulate.nuisance import (
    AMPLITUDE_RATIO,
    NUISANCE_PRIORS,
    OPENING_PER_CELL,
    latin_hypercube,
    nominal_sample,
    priors_record,
)


def test_opening_per_cell_is_the_printed_cells_inscribed_circle():
    # a finely resolved single cell (the polyline limit), zero filament width
    lat = sinusoidal_lattice(2, 1.0, AMPLITUDE_RATIO, 160, "expanding")
    d = float(passing_diameters(lat.network.nodes, lat.edge_chains, 2, 0.0)[0])
    assert d == pytest.approx(OPENING_PER_CELL, abs=1e-3)


def test_cell_size_gives_the_stated_opening():
    s = nominal_sample()
    lat = sinusoidal_lattice(2, s.cell_size, s.amplitude, 160, "contracting")
    d = float(passing_diameters(lat.network.nodes, lat.edge_chains, 2, 0.5 * s.filament_width)[0])
    assert d == pytest.approx(s.cold_opening, abs=0.01)


def test_every_prior_states_its_range_unit_and_source():
    for p in NUISANCE_PRIORS.values():
        assert p.low < p.high and p.unit and len(p.source) > 30
    names = {r["name"] for r in priors_record()}
    assert names == set(NUISANCE_PRIORS) | {"cell_size"}
    lo, hi = next(r["range"] for r in priors_record() if r["name"] == "cell_size")
    assert 6.0 < lo < hi < 9.5


def test_latin_hypercube_uses_every_stratum_once_per_input():
    n = 12
    samples = latin_hypercube(n, seed=3)
    assert samples == latin_hypercube(n, seed=3)  # deterministic
    for name, p in NUISANCE_PRIORS.items():
        u = np.sort([(getattr(s, name) - p.low) / (p.high - p.low) for s in samples])
        assert np.allclose(u, (np.arange(n) + 0.5) / n)
    with pytest.raises(ValueError, match="count"):
        latin_hypercube(1)
