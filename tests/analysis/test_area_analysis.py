"""Projected lattice areas, boundary loops and unit apertures."""

from __future__ import annotations

import numpy as np
import pytest
from _analysis_builders import random_rotation, sinusoidal_lattice

from rotomorph.analysis.area import (
    lattice_boundary_loop,
    loop_area,
    normalized_area,
    polygon_area,
    unit_apertures,
    unit_cell_loops,
)
from rotomorph.errors import InvalidParameterError


def test_polygon_area_of_unit_square_in_any_pose():
    square = np.array([[0, 0, 0], [2, 0, 0], [2, 3, 0], [0, 3, 0]], dtype=float)
    assert polygon_area(square) == pytest.approx(6.0)
    rot = random_rotation(7)
    assert polygon_area(square @ rot.T + 10.0) == pytest.approx(6.0)
    assert polygon_area(square[::-1]) == pytest.approx(6.0)


def test_degenerate_polygons_have_zero_area():
    assert polygon_area(np.zeros((0, 3))) == 0.0
    assert polygon_area(np.eye(3)[:2]) == 0.0
    assert polygon_area(np.linspace([0, 0, 0], [1, 1, 1], 5)) == 0.0


def test_boundary_loop_walks_the_perimeter(lattice):
    pos, chains = lattice
    loop = lattice_boundary_loop(chains, 5)
    assert len(loop) == 16 * 11  # 16 boundary edges, 11 segments each
    assert len(set(loop.tolist())) == len(loop)
    corners = [0, 20, 24, 4]
    assert all(c in loop for c in corners)
    assert loop[0] == 0 and loop[11] == 5  # along +x first
    # the sine bulges cancel over a full period: the area is exactly (n-1)^2 l^2
    assert loop_area(pos, loop) == pytest.approx(1600.0, rel=1e-12)


def test_boundary_is_counter_clockwise(lattice):
    pos, chains = lattice
    p = pos[lattice_boundary_loop(chains, 5)]
    signed = 0.5 * np.sum(p[:, 0] * np.roll(p[:, 1], -1) - np.roll(p[:, 0], -1) * p[:, 1])
    assert signed > 0


def test_normalized_area_scales_quadratically(lattice):
    pos, chains = lattice
    loop = lattice_boundary_loop(chains, 5)
    assert normalized_area(pos * 1.4, pos, loop) == pytest.approx(1.96)
    rot = random_rotation(1)
    assert normalized_area(0.85 * pos @ rot.T, pos, loop) == pytest.approx(0.85**2)


def test_normalized_area_by_stretching_x_only(lattice):
    pos, chains = lattice
    loop = lattice_boundary_loop(chains, 5)
    stretched = pos * [1.5, 1.0, 1.0]
    assert normalized_area(stretched, pos, loop) == pytest.approx(1.5)


def test_zero_reference_area_raises(lattice):
    pos, chains = lattice
    flat = pos * [1.0, 0.0, 0.0]
    with pytest.raises(InvalidParameterError, match="no area"):
        normalized_area(pos, flat, lattice_boundary_loop(chains, 5))


def test_unit_apertures(lattice):
    pos, chains = lattice
    areas = unit_apertures(pos, chains, 5)
    assert isinstance(areas, list) and len(areas) == 16
    np.testing.assert_allclose(areas, 100.0, rtol=1e-12)
    moved = pos.copy()
    moved[12] += [3.0, 3.0, 0.0]  # the centre branch node, corner of cells 5, 6, 9, 10
    changed = np.flatnonzero(~np.isclose(unit_apertures(moved, chains, 5), 100.0))
    assert changed.tolist() == [5, 6, 9, 10]
    loops = unit_cell_loops(chains, 5)
    assert len(loops[0]) == 44


def test_unit_apertures_of_a_two_by_two_grid():
    pos, chains = sinusoidal_lattice(n=2, spacing=4.0, amplitude=0.5, ghosts=6)
    assert unit_apertures(pos, chains, 2) == [pytest.approx(16.0)]


def test_missing_chain_and_bad_grid_raise(lattice):
    _, chains = lattice
    with pytest.raises(InvalidParameterError, match="no chain joins"):
        lattice_boundary_loop(chains[1:], 5)
    with pytest.raises(InvalidParameterError, match="n"):
        lattice_boundary_loop(chains, 1)


def test_with_the_design_layers_lattice():
    from rotomorph.design.lattices import sinusoidal_lattice as design_lattice

    lat = design_lattice(n=5, spacing=5.0, amplitude=1.25)
    pos = lat.network.nodes
    loop = lattice_boundary_loop(lat.edge_chains, 5)
    assert len(loop) == 16 * 11
    assert loop_area(pos, loop) == pytest.approx(400.0, rel=1e-12)
    np.testing.assert_allclose(unit_apertures(pos, lat.edge_chains, 5), 25.0, rtol=1e-12)
    assert normalized_area(pos * 1.3, pos, loop) == pytest.approx(1.69)
