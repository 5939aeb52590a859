"""The rod model of a printed lattice: counts, modes, directors, stiffness, derivatives."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg as sl

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice import edge_model, lattice_model
from rotomorph.lattice.model import interface_normals, paper_modulus, stencil_sides
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.objective import RodObjective


def _dense(h):
    return h.to_dense() if hasattr(h, "to_dense") else h.toarray()


def test_paper_lattice_counts():
    lm = lattice_model(sinusoidal_lattice())
    net, st = lm.model.network, lm.model.stencils
    assert net.n_nodes == 425
    assert net.n_edges == 440
    assert int(st.junction.sum()) == 94 == lm.lattice.n_junction_pairs
    assert st.count == 94 + 40 * 10  # one rod vertex per ghost node


def test_printed_state_is_stress_free_with_only_rigid_modes():
    """m1 = +z: no stencil sits at a twist of pi, so only the 6 rigid motions cost nothing."""
    for n, ghosts in ((2, 2), (3, 3), (3, 2)):
        lm = lattice_model(sinusoidal_lattice(n=n, ghost_nodes=ghosts, pattern="dome"))
        model = lm.model
        obj = RodObjective(model, model.reference_state(), Supports(), Loads())
        energy, grad, hess = obj.evaluate(obj.vector(), True, True)
        assert energy == pytest.approx(0.0, abs=1e-20)
        assert np.abs(grad).max() < 1e-12
        w = sl.eigh(_dense(hess), np.diag(obj.metric()), eigvals_only=True)
        assert int(np.sum(w < 1e-9 * w[-1])) == 6


def test_interface_normals_and_sides():
    lat = sinusoidal_lattice(pattern="dome")
    n = interface_normals(lat)
    side = lat.segment_side
    assert np.allclose(n[side == 0], [0.0, 0.0, 1.0])
    inplane = side != 0
    assert np.allclose(n[inplane, 2], 0.0)
    lm = lattice_model(lat)
    s = stencil_sides(side, lm.model)
    assert np.all(s[lm.model.stencils.junction] == 0)
    assert np.all(np.abs(s[lm.rod_vertex]) == 1)  # even ghost_nodes: flips inside segments
    # unit curvature toward the active side is a unit in-plane curvature (kappa2 with m1 = +z)
    b1, b2 = lm.side_basis
    assert np.allclose(b1[lm.rod_vertex], 0.0, atol=1e-12)
    assert np.allclose(np.abs(b2[lm.rod_vertex]), 1.0, atol=0.05)


def test_stiffness_options():
    lat = sinusoidal_lattice()
    paper = lattice_model(lat, layers=1, youngs_modulus=2.0).model
    r = lat.radius
    assert paper.bending_stiffness1[0] == pytest.approx(2.0 * np.pi * r**4 / 4)
    assert paper.twist_stiffness[0] == pytest.approx(2.0 / 3.0 * np.pi * r**4 / 2)
    assert paper.axial_stiffness[0] == pytest.approx(2.0 * np.pi * r**2)
    three = lattice_model(lat, youngs_modulus=2.0).model  # lattice.layers == 3
    assert np.allclose(three.bending_stiffness1, 3 * paper.bending_stiffness1)
    assert paper_modulus() > 0
    janus = lattice_model(lat, stiffness="janus", layers=1).model
    side = lat.segment_side
    # B_n (toward the in-plane interface normal) pairs with kappa2 where n is in-plane
    assert np.all(janus.bending_stiffness2[side != 0] < janus.bending_stiffness1[side != 0])
    assert np.all(janus.bending_stiffness1[side == 0] < janus.bending_stiffness2[side == 0])
    with pytest.raises(InvalidParameterError, match="stiffness"):
        lattice_model(lat, stiffness="steel")  # type: ignore[arg-type]
    with pytest.raises(InvalidParameterError, match="layers"):
        lattice_model(lat, layers=0)


def test_edge_model_is_one_chain():
    lat = sinusoidal_lattice(pattern="dome")
    em = edge_model(lat, 0)
    assert em.model.network.n_nodes == lat.ghost_nodes + 2
    assert not em.model.stencils.junction.any()
    assert bool(em.expanding.all()) == (lat.edge_mode[0] == "expanding")
    with pytest.raises(InvalidParameterError, match="edge"):
        edge_model(lat, 40)


def test_network_derivatives_match_finite_differences():
    """Gradient and Hessian of a small actuated lattice (3x3, 2 ghost nodes, junctions)."""
    from dataclasses import replace

    from rotomorph.lattice import get_actuation
    from rotomorph.lattice.heating import perturbed_state

    lat = sinusoidal_lattice(n=3, ghost_nodes=2, spacing=5.0, amplitude=1.25, pattern="dome")
    lm = lattice_model(lat)
    model = get_actuation("additive").natural(lm, 0.5)
    rng = np.random.default_rng(7)
    moved = perturbed_state(model, 0.3 * rng.standard_normal((model.network.n_nodes, 3)))
    state = replace(moved, theta=0.3 * rng.standard_normal(model.network.n_edges))
    obj = RodObjective(model, state, Supports(), Loads())
    # frames are transported from the base, so the DER derivatives are exact there
    q0 = obj.vector()
    _, g, h = obj.evaluate(q0, True, True)
    hd = _dense(h)
    step = 1e-6
    n = len(q0)
    fd_g = np.empty(n)
    fd_h = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        fp, gp, _ = obj.evaluate(q0 + e, True, False)
        fm, gm, _ = obj.evaluate(q0 - e, True, False)
        fd_g[k] = (fp - fm) / (2 * step)
        fd_h[:, k] = (gp - gm) / (2 * step)
    assert np.linalg.norm(fd_g - g) <= 1e-6 * np.linalg.norm(g)
    # with frames re-based at every iterate the Hessian is the symmetric part of the Jacobian
    assert np.allclose(hd, hd.T, rtol=0, atol=1e-12 * np.abs(hd).max())
    assert np.linalg.norm(0.5 * (fd_h + fd_h.T) - hd) <= 1e-6 * np.linalg.norm(hd)
