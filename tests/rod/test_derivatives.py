"""Analytic gradients and Hessians of the DER energy against central finite differences.

The energy is evaluated with reference frames transported in time from a fixed base (exactly
what the solver minimises between re-basings); the Hessian is compared with the symmetric part
of the finite-difference Jacobian of the gradient and with second differences of the energy.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from _rod_builders import anisotropic_model, displaced_objective, random_chain

from rotomorph.design.network import Network
from rotomorph.rod.model import Model
from rotomorph.solve.linalg import BandedMatrix


def _dense(H):
    return H.to_dense() if isinstance(H, BandedMatrix) else H.toarray()


def _networks(rng):
    chain = Network.chain(random_chain(rng, 7))
    # a 4-valent junction (node 0) with two 2-segment arms and two 1-segment arms, plus a
    # degree-2 branch node (node 7, flagged) joining two segments at 90 degrees
    nodes = np.array(
        [
            [0, 0, 0],
            [1, 0.1, 0],
            [2, 0.3, 0.2],
            [-1, 0, 0.1],
            [0, 1, -0.1],
            [0, -1.1, 0.2],
            [-1.8, 0.4, 0.3],
            [0.1, 1.0, 1.0],
        ],
        dtype=float,
    )
    edges = np.array([[0, 1], [1, 2], [3, 0], [0, 4], [5, 0], [6, 3], [4, 7]])
    branch = np.zeros(len(nodes), dtype=bool)
    branch[[0, 7]] = True
    branch[4] = True
    return [chain, Network(nodes, edges, branch)]


@pytest.mark.parametrize("which", [0, 1], ids=["chain", "junctions"])
def test_gradient_matches_central_differences(rng, which):
    net = _networks(rng)[which]
    model = anisotropic_model(net, rng)
    obj, q = displaced_objective(model, rng)
    _, g, _ = obj.evaluate(q, True, False)
    h = 1e-6
    fd = np.empty_like(g)
    for i in range(len(q)):
        e = np.zeros_like(q)
        e[i] = h
        fd[i] = (obj.evaluate(q + e, False, False)[0] - obj.evaluate(q - e, False, False)[0]) / (
            2 * h
        )
    assert np.linalg.norm(g - fd) <= 1e-6 * np.linalg.norm(g)


@pytest.mark.parametrize("which", [0, 1], ids=["chain", "junctions"])
def test_hessian_matches_jacobian_of_gradient(rng, which):
    net = _networks(rng)[which]
    model = anisotropic_model(net, rng)
    obj, q = displaced_objective(model, rng)
    _, _, H = obj.evaluate(q, True, True)
    H = _dense(H)
    assert np.allclose(H, H.T, rtol=0, atol=1e-12 * np.abs(H).max())
    h = 1e-6
    J = np.empty_like(H)
    for i in range(len(q)):
        e = np.zeros_like(q)
        e[i] = h
        J[:, i] = (obj.evaluate(q + e, True, False)[1] - obj.evaluate(q - e, True, False)[1]) / (
            2 * h
        )
    Js = 0.5 * (J + J.T)
    assert np.linalg.norm(H - Js) <= 1e-6 * np.linalg.norm(H)


def test_hessian_second_differences_and_taylor_slope(rng):
    net = _networks(rng)[0]
    model = anisotropic_model(net, rng)
    obj, q = displaced_objective(model, rng)
    f0, g, H = obj.evaluate(q, True, True)
    H = _dense(H)
    for _ in range(5):
        v = rng.normal(size=len(q))
        v /= np.linalg.norm(v)
        h = 1e-4
        fp = obj.evaluate(q + h * v, False, False)[0]
        fm = obj.evaluate(q - h * v, False, False)[0]
        assert abs((fp - 2 * f0 + fm) / h**2 - v @ H @ v) <= 1e-5 * max(1.0, abs(v @ H @ v))
    # Taylor remainder of the quadratic model decays with slope 3 (first-order model: slope 2)
    v = rng.normal(size=len(q))
    v /= np.linalg.norm(v)
    hs = np.array([4e-3, 2e-3, 1e-3, 5e-4])
    r1, r2 = [], []
    for h in hs:
        fh = obj.evaluate(q + h * v, False, False)[0]
        r1.append(abs(fh - f0 - h * g @ v))
        r2.append(abs(fh - f0 - h * g @ v - 0.5 * h**2 * v @ H @ v))
    s1 = np.polyfit(np.log(hs), np.log(r1), 1)[0]
    s2 = np.polyfit(np.log(hs), np.log(r2), 1)[0]
    assert s1 == pytest.approx(2.0, abs=0.1)
    assert s2 == pytest.approx(3.0, abs=0.2)


@pytest.mark.parametrize("which", [0, 1], ids=["chain", "junctions"])
def test_gauss_newton_hessian_is_the_exact_one_at_a_stress_free_state(rng, which):
    """Where every strain is at its natural value the second-derivative terms of the strains
    carry zero weight: Gauss-Newton and exact Hessians coincide, term by term (B1, B2, C, EA
    all different per edge). Positive semidefiniteness alone holds for any truncation."""
    from rotomorph.solve.loads import Loads, Supports
    from rotomorph.solve.objective import RodObjective

    net = _networks(rng)[which]
    ne = net.n_edges
    model = Model(
        net,
        bending_stiffness1=rng.uniform(0.5, 2.0, ne),
        bending_stiffness2=rng.uniform(2.0, 4.0, ne),
        twist_stiffness=rng.uniform(0.3, 1.0, ne),
        axial_stiffness=rng.uniform(20.0, 60.0, ne),
    )  # natural values: the printed ones
    obj = RodObjective(model, model.reference_state(), Supports(), Loads())
    q = obj.vector()
    exact = _dense(obj.evaluate(q, True, True)[2])
    gn = _dense(obj.convex_hessian(q))
    assert np.abs(exact).max() > 1.0
    np.testing.assert_allclose(gn, exact, rtol=0, atol=1e-10 * np.abs(exact).max())
    if which == 0:
        # a straight chain stretched by 10 %: bending and twist stay natural, and stretching
        # in tension keeps its transverse (string) stiffness: still the exact Hessian
        s = np.cumsum(rng.uniform(0.5, 1.5, 7))
        straight = Model.chain(
            np.c_[s, 0 * s, 0 * s],
            bending_stiffness1=1.0,
            bending_stiffness2=3.0,
            twist_stiffness=0.7,
            axial_stiffness=40.0,
        )
        ref = straight.reference_state()
        stretched = replace(ref, positions=1.1 * ref.positions)
        obj = RodObjective(straight, stretched, Supports(), Loads())
        q = obj.vector()
        exact = _dense(obj.evaluate(q, True, True)[2])
        np.testing.assert_allclose(_dense(obj.convex_hessian(q)), exact, rtol=0,
                                   atol=1e-10 * np.abs(exact).max())  # fmt: skip


def test_gauss_newton_hessian_is_positive_semidefinite(rng):
    net = _networks(rng)[0]
    model = anisotropic_model(net, rng)
    obj, q = displaced_objective(model, rng)
    Hgn = _dense(obj.convex_hessian(q))
    assert np.linalg.eigvalsh(Hgn).min() >= -1e-10 * np.abs(Hgn).max()
    H = _dense(obj.evaluate(q, True, True)[2])
    assert np.linalg.eigvalsh(H).min() < 0  # the displaced state is not convex: GN differs


@pytest.mark.parametrize("which", [0, 1], ids=["chain", "junctions"])
def test_energy_only_evaluation_is_the_full_one_to_the_bit(rng, which):
    """A line-search trial (no gradient, no Hessian) takes the energy-only kernel: same energy,
    same transported frames and reference twists (which ``accept`` re-bases on) as the full
    evaluation, to the last bit, on random states far from the base and with twist turned past
    the unwrapping range."""
    net = _networks(rng)[which]
    model = anisotropic_model(net, rng)
    obj, q = displaced_objective(model, rng)
    for scale in (1e-3, 0.1, 0.5):
        for twist in (0.1, 4.0):
            dq = rng.normal(0.0, scale, len(q))
            dq[np.isin(obj.free, model.layout.theta)] *= twist / scale
            trial = q + dq
            frames = []
            energies = []
            for need_grad, need_hess in ((False, 0), (True, 0), (True, 1), (True, 2)):
                energies.append(obj.evaluate(trial, need_grad, need_hess)[0])
                frames.append([a.copy() for a in (obj._t, obj._d1, obj._m1, obj._m2, obj._mref)])
            assert np.isfinite(energies[0])
            assert all(e == energies[0] for e in energies[1:]), energies
            for other in frames[1:]:
                for a, b in zip(frames[0], other, strict=True):
                    np.testing.assert_array_equal(a, b)
