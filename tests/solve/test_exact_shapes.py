"""The static solver against exact solutions: helix (with its convergence order), circle,
anisotropic stiffness, cantilever under a tip moment and under self-weight."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.analysis.shape import fit_helix
from rotomorph.rod.cases import HelixCase
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.static import solve_static

CASE = HelixCase()


def helix_model(n: int, b2_factor: float = 1.0) -> Model:
    return CASE.model(n, b2_factor)


def _helix_errors(n: int, b2_factor: float = 1.0) -> tuple[float, float, int]:
    res = solve_static(helix_model(n, b2_factor))
    fit = fit_helix(res.positions)
    r, p = CASE.helix_radius, CASE.helix_pitch
    return abs(fit.radius - r) / r, abs(abs(fit.pitch) - p) / p, res.iterations


def test_free_rod_becomes_the_helix_within_5e_3():
    er, ep, iterations = _helix_errors(101)
    assert er < 5e-3 and ep < 5e-3
    assert iterations <= 20  # pinned: a Hessian regression shows up here first


def test_helix_converges_with_second_order_in_n():
    ns = np.array([26, 51, 101, 201])
    errs = np.array([_helix_errors(int(n))[0] for n in ns])
    h = 1.0 / (ns - 1)
    order = np.polyfit(np.log(h), np.log(errs), 1)[0]
    assert order == pytest.approx(2.0, abs=0.25)


def test_helix_shape_does_not_depend_on_anisotropy():
    # free rod: k = k_bar for any stiffness matrix
    er, ep, _ = _helix_errors(101, b2_factor=3.7)
    assert er < 5e-3 and ep < 5e-3


@pytest.mark.parametrize("b2", [1.0, 4.0])
def test_natural_curvature_alone_gives_a_circular_arc(b2):
    n, kappa = 61, 0.4
    s = np.linspace(0, 10.0, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=1e-2,
        bending_stiffness2=b2 * 1e-2,
        twist_stiffness=7e-3,
        axial_stiffness=10.0,
    )
    model = model.with_natural(curvature1=np.full(n - 2, kappa))
    x = solve_static(model).positions
    # circle through the nodes: all at the same distance from the centroid of the arc's circle
    fit = fit_helix(x)
    assert abs(fit.pitch) < 1e-6
    assert fit.radius == pytest.approx(1 / kappa, rel=2e-3)
    # the rod bends toward m1 = +z (space-parallel director of a straight x-rod): planar in xz
    assert np.ptp(x[:, 1]) < 1e-8


def test_cantilever_tip_moment_gives_a_circular_arc():
    # clamped at s = 0 along x, tip moment M about z: theta(s) = M s / B
    n, length, B = 51, 10.0, 2e-2
    s = np.linspace(0, length, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=B,
        bending_stiffness2=B,
        twist_stiffness=B / 1.5,
        axial_stiffness=1e3,
    )
    M = 0.5 * np.pi * B / length  # quarter circle
    res = solve_static(model, Supports.clamp_ends(n), Loads(moments=[(n - 1, (0, 0, M))]))
    tip = res.positions[-1]
    rho = B / M
    # DER clamps the first edge's frame, i.e. the tangent at its midpoint s0 = l/2
    s0 = 0.5 * length / (n - 1)
    arc = length - s0
    expected = np.array([s0 + rho * np.sin(arc / rho), rho * (1 - np.cos(arc / rho)), 0.0])
    assert np.linalg.norm(tip - expected) / length < 5e-3
    assert res.iterations <= 15


def test_cantilever_self_weight_small_deflection():
    # w L^4 / (8 B) tip deflection of a clamped-free beam under its weight (Euler-Bernoulli)
    n, length, radius, E = 81, 10.0, 0.3, 30.0
    area, inertia = np.pi * radius**2, np.pi * radius**4 / 4
    s = np.linspace(0, length, n)
    B = E * inertia
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=B,
        bending_stiffness2=B,
        twist_stiffness=B / 1.5,
        axial_stiffness=E * area * 1e3,
    )
    grav = Gravity(density=1.1, area=area, fluid_density=0.0)
    w = grav.line_weight(1)[0]
    # the load itself, by hand (not from line_weight, which the deflection below would only
    # echo): 1.1 g/cm^3 = 1.1e-6 kg/mm^3, times the area (mm^2) and g = 9.80665 m/s^2 -> N/mm
    assert w == pytest.approx(1.1e-6 * area * 9.80665, rel=1e-12)
    res = solve_static(model, Supports.clamp_ends(n), Loads(gravity=grav))
    expected = w * length**4 / (8 * B)
    assert expected < 0.05 * length  # small-deflection regime
    # the first edge is clamped, so the beam is effectively shorter by half an edge
    assert -res.positions[-1, 2] == pytest.approx(expected, rel=3e-2)


def test_equilibrium_is_stable_and_gradient_vanishes_at_natural_state():
    model = helix_model(41)
    res = solve_static(model)
    from rotomorph.solve.loads import Loads as _L
    from rotomorph.solve.objective import RodObjective

    obj = RodObjective(model, res.state, Supports(), _L())
    _, g, H = obj.evaluate(obj.vector(), True, True)
    assert np.linalg.norm(g) < 1e-8
    eig = np.linalg.eigvalsh(H.to_dense())
    # six rigid-body zero modes, everything else positive: a stable minimum
    assert np.sum(eig < -1e-10 * eig.max()) == 0
    assert np.sum(eig < 1e-9 * eig.max()) == 6
