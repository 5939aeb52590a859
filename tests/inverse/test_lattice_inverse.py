"""Adjoint design of lattices: exact gradients, misfit gradients, targets and round trips."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidDesignError
from rotomorph.inverse.lattice import (
    _Equilibria,
    design_lattice,
    dome,
    height_map,
    lattice_blend,
    misfit_and_gradient,
    surface_misfit,
)
from rotomorph.inverse.run import lattice_design_file


@pytest.fixture(scope="module")
def small():
    lat = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    return lat, lattice_blend(lat)


def _gradient(blend, eq, c, target, size):
    res = eq(c)
    j, g = misfit_and_gradient(blend, c, res, target, size)
    return j, g, res.state


def test_misfit_gradient_matches_central_differences(small):
    lat, _ = small
    rng = np.random.default_rng(1)
    x = lat.network.nodes.copy()
    x[:, 2] = 0.02 * np.sum((x[:, :2] - 5.0) ** 2, axis=1) + rng.normal(0, 0.05, len(x))
    x = x @ np.array([[1, 0, 0], [0, 0.96, -0.28], [0, 0.28, 0.96]]).T + 3.0  # tilted, moved
    target = dome(0.05)
    _, g, _ = surface_misfit(x, target, 10.0)
    h = 1e-4
    for i, k in [(3, 2), (20, 0), (40, 1)]:
        xp, xm = x.copy(), x.copy()
        xp[i, k] += h
        xm[i, k] -= h
        fd = (surface_misfit(xp, target, 10.0)[0] - surface_misfit(xm, target, 10.0)[0]) / (2 * h)
        assert g[i, k] == pytest.approx(fd, rel=1e-4, abs=1e-10)


def test_adjoint_gradient_matches_central_differences(small):
    lat, blend = small
    eq = _Equilibria(blend)
    rng = np.random.default_rng(3)
    base = np.array([1.0 if m == "expanding" else -1.0 for m in lat.edge_mode])
    c = np.clip(0.7 * base + rng.uniform(-0.1, 0.1, blend.n_edges), -1, 1)
    target = dome(0.04)
    j, g, state = _gradient(blend, eq, c, target, 10.0)

    def central(e, h):
        vals = []
        for sgn in (1, -1):
            cc = c.copy()
            cc[e] += sgn * h
            eq.last = (c, state)
            vals.append(surface_misfit(eq(cc).positions, target, 10.0)[0])
        return (vals[0] - vals[1]) / (2 * h)

    for e in (0, 5, 9):
        # Richardson extrapolation of two central differences: O(h^4), above the solver noise
        fd = (4 * central(e, 5e-4) - central(e, 1e-3)) / 3
        assert g[e] == pytest.approx(fd, rel=1e-5, abs=1e-12 * abs(j))


def test_design_is_printable_verified_and_written_as_a_design_file():
    start = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    des = design_lattice(start, dome(0.1), max_iterations=3)
    finite = des.objective_history[np.isfinite(des.objective_history)]
    assert finite.min() < finite[0]  # the optimiser improved on the start
    assert set(np.unique(des.modes)) <= {-1.0, 1.0}
    assert des.stable
    file = lattice_design_file(des, "dome")
    assert file.lattice is not None and file.lattice.pattern == "custom"
    assert [m == "expanding" for m in file.lattice.edge_modes] == list(des.modes > 0)
    # the written design is the verified one
    assert file.lattice.to_lattice().edge_mode == des.lattice.edge_mode


def test_bad_lattice_targets_have_clear_errors(small):
    lat, _ = small
    with pytest.raises(InvalidDesignError, match="close on itself"):
        design_lattice(lat, dome(1.0))
    x = np.linspace(-3, 3, 6)
    with pytest.raises(InvalidDesignError, match="extend the grid"):
        design_lattice(lat, height_map(x, x, np.zeros((6, 6))))
    x = np.linspace(-8, 8, 6)
    with pytest.raises(InvalidDesignError, match="more than the lattice size"):
        design_lattice(lat, height_map(x, x, np.outer(x, x)))
    with pytest.raises(InvalidDesignError, match="positive curvature"):
        dome(-0.1)


def test_blend_at_printable_modes_is_the_printed_lattice_model(small):
    """At c = ±1 the blend gives exactly the natural values the forward model builds."""
    from rotomorph.lattice.actuation import DEFAULT_ACTUATION, get_actuation
    from rotomorph.lattice.model import lattice_model

    lat, blend = small
    act = get_actuation(DEFAULT_ACTUATION)
    rng = np.random.default_rng(5)
    for _ in range(3):
        modes = rng.choice([-1.0, 1.0], blend.n_edges)
        pattern = {e: ("expanding" if m > 0 else "contracting") for e, m in enumerate(modes)}
        ref = act.natural(lattice_model(lattice_design(lat, pattern)), act.end)
        k, rest = blend.natural(modes)
        assert np.allclose(k, np.stack(ref.integrated_natural(), axis=1), atol=1e-12)
        assert np.allclose(rest, ref.rest_length, atol=1e-12)


def lattice_design(lat, pattern):
    return sinusoidal_lattice(
        n=lat.n,
        spacing=lat.spacing,
        amplitude=lat.amplitude,
        ghost_nodes=lat.ghost_nodes,
        pattern=pattern,
    )
