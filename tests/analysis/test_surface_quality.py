"""Is a lattice state a surface: the quadratic fit's residual and edges crossing themselves."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.analysis.surface import crosses_itself, surface_quality
from rotomorph.design.lattices import sinusoidal_lattice


def test_a_loop_crosses_itself_a_wave_does_not() -> None:
    s = np.linspace(0.0, 1.0, 40)
    wave = np.column_stack([s, 0.2 * np.sin(2 * np.pi * s)])
    assert not crosses_itself(wave)
    t = np.linspace(0.0, 3.2 * np.pi, 80)
    loop = np.column_stack([0.3 * np.cos(t) + 0.01 * t, 0.3 * np.sin(t)])
    assert crosses_itself(loop)
    assert not crosses_itself(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]]))  # a corner


def test_a_lattice_on_a_sphere_is_a_surface_one_folded_is_not() -> None:
    lat = sinusoidal_lattice(5, pattern="dome")
    x = lat.network.nodes.copy()
    c = x[lat.branch_indices].mean(axis=0)
    r2 = np.sum((x[:, :2] - c[:2]) ** 2, axis=1)
    dome = x.copy()
    dome[:, 2] = -r2 / (2 * 30.0)  # a spherical cap (small slope) of radius 30 mm
    q = surface_quality(dome, lat.branch_indices, lat.edge_chains)
    assert q.is_surface and q.relative_residual < 0.01 and q.rise > 1.0
    assert q.fit.gaussian_sign == 1 and not q.crossing_edges
    assert "no edge crosses itself" in q.text()
    # fold the rim branch nodes down like a drum's sides: the quadratic no longer fits
    folded = dome.copy()
    rim = np.sqrt(r2) > 8.0
    folded[rim, 2] -= 6.0
    bad = surface_quality(folded, lat.branch_indices, lat.edge_chains)
    assert bad.relative_residual > 0.1 and not bad.is_surface
    # coil one edge into a loop in the plane
    coiled = dome.copy()
    chain = lat.edge_chains[3]
    a, b = coiled[chain[0], :2], coiled[chain[-1], :2]
    t = np.linspace(0.0, 1.0, len(chain))
    mid = 0.5 * (a + b)
    ring = np.column_stack([np.cos(2.4 * np.pi * t), np.sin(2.4 * np.pi * t)]) * 1.5
    coiled[chain[1:-1], :2] = (mid + ring + np.outer(t, b - a) * 0.0)[1:-1]
    q2 = surface_quality(coiled, lat.branch_indices, lat.edge_chains)
    assert q2.crossing_edges == (3,) and not q2.is_surface
    assert q2.relative_residual == pytest.approx(q.relative_residual)
