"""Largest ball passing through a cell: exact inscribed circles, filament radius, lattices."""

from __future__ import annotations

import numpy as np
import pytest
from _analysis_builders import random_rotation

from rotomorph.analysis.aperture import inscribed_radius, loop_opening, passing_diameters
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError


def test_inscribed_circles_of_exact_shapes():
    square = np.array([[0, 0], [2, 0], [2, 2], [0, 2]], dtype=float)
    assert inscribed_radius(square) == pytest.approx(1.0, rel=1e-3)
    # 3-4-5 right triangle: r = (a + b - c) / 2 = 1
    assert inscribed_radius(np.array([[0, 0], [3, 0], [0, 4]], float)) == pytest.approx(
        1.0, rel=2e-3
    )
    # a long thin rectangle: half its width, wherever along it the centre is
    assert inscribed_radius(np.array([[0, 0], [10, 0], [10, 1], [0, 1]], float)) == pytest.approx(
        0.5, rel=2e-3
    )
    assert inscribed_radius(np.array([[0, 0], [1, 0], [2, 0]], float)) == 0.0


def test_loop_opening_subtracts_the_filament_and_ignores_pose():
    phi = np.linspace(0, 2 * np.pi, 120, endpoint=False)
    ring = np.c_[3 * np.cos(phi), 3 * np.sin(phi), 0 * phi] @ random_rotation(3).T + 5.0
    loop = np.arange(120)
    assert loop_opening(ring, loop, 0.3) == pytest.approx(2 * (3 - 0.3), rel=2e-3)
    assert loop_opening(ring, loop, 5.0) == 0.0  # filaments thicker than the hole: closed
    with pytest.raises(InvalidParameterError, match="filament_radius"):
        loop_opening(ring, loop, -1.0)


def test_straight_lattice_cells_pass_spacing_minus_diameter():
    lat = sinusoidal_lattice(n=3, spacing=5.0, amplitude=0.0, ghost_nodes=3)
    d = passing_diameters(lat.network.nodes, lat.edge_chains, 3, 0.3)
    np.testing.assert_allclose(d, 5.0 - 0.6, rtol=2e-3)
    # a sinusoidal edge bulges into one neighbour and out of the other, but every cell of the
    # printed expanding lattice is the same shape
    wavy = sinusoidal_lattice(n=3, spacing=5.0, amplitude=1.25)
    d = passing_diameters(wavy.network.nodes, wavy.edge_chains, 3, 0.3)
    assert np.ptp(d) < 2e-3 and 0 < d[0] < 5.0 - 0.6  # grid search: ~2e-4 of the cell size
