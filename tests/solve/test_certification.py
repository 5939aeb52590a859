"""Every equilibrium the solver returns is certified a minimum; saddles are left.

Exact references: the clamped–free elastica (elliptic integrals), the Euler load of the same
column from the tangent stiffness, the free–free beam's bending eigenvalues, Rosenbrock's
Hessian, a two-variable saddle with known minima.
"""

from __future__ import annotations

import doctest

import numpy as np
import pytest
from scipy.optimize import rosen, rosen_der, rosen_hess

import rotomorph.solve.stability as stability_module
from rotomorph.errors import InvalidParameterError
from rotomorph.rod.cases import EulerColumnCase
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import FunctionObjective, NewtonOptions, minimize
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.result import Status
from rotomorph.solve.stability import stability
from rotomorph.solve.static import solve_static

CASE = EulerColumnCase()
E, RADIUS, LENGTH = CASE.young, CASE.radius, CASE.length  # MPa, mm, mm
B = CASE.bending_stiffness  # N mm²
P_CR = CASE.euler_load  # clamped–free Euler load (N)
RAMP = NewtonOptions(rtol=1e-7, max_iterations=300)  # the lattice ramps' tolerance
column = CASE.model
elastica_tip = CASE.elastica_tip


@pytest.mark.parametrize("options", [None, RAMP], ids=["default-tol", "ramp-tol"])
def test_straight_column_above_euler_load_buckles_to_the_elastica(options):
    n = 41
    model = column(n)
    res = solve_static(
        model, Supports.clamp_ends(n), Loads(forces=[(n - 1, (-3 * P_CR, 0.0, 0.0))]), None, options
    )
    assert res.status is Status.CONVERGED and res.stable and res.escapes >= 1
    x_tip = res.positions[-1, 0] / LENGTH
    y_tip = np.hypot(*res.positions[-1, 1:]) / LENGTH
    x_ref, y_ref = elastica_tip(3.0)  # (-0.2041, 0.7074): the tip swings behind the clamp
    assert y_tip == pytest.approx(y_ref, abs=1.5e-3)
    assert x_tip == pytest.approx(x_ref, abs=5e-3)  # O(h^2): 2.4e-3 at n = 41
    assert res.iterations <= 15  # pinned (11-12 with one escape)


def test_straight_column_below_euler_load_stays_straight_and_stable():
    n = 41
    res = solve_static(
        column(n), Supports.clamp_ends(n), Loads(forces=[(n - 1, (-0.8 * P_CR, 0.0, 0.0))])
    )
    assert res.stable and res.escapes == 0
    assert np.abs(res.positions[:, 1:]).max() == 0.0
    assert res.eigenvalues[0] > 0


def test_euler_load_from_the_tangent_stiffness():
    """The lowest eigenvalue of the straight compressed column changes sign at P_cr."""
    n = 41
    model, supports = column(n), Supports.clamp_ends(n)
    lowest = []
    for f in (0.9, 1.1):
        loads = Loads(forces=[(n - 1, (-f * P_CR, 0.0, 0.0))])
        straight = solve_static(
            model, supports, loads, options=NewtonOptions(check_stability=False)
        )
        res = stability(model, straight.state, supports, loads, count=2)
        assert res.stable == (f < 1) and res.rigid_modes == 0
        # isotropic section: the two bending planes give a double eigenvalue
        assert res.eigenvalues[1] == pytest.approx(res.eigenvalues[0], rel=1e-6)
        lowest.append(res.eigenvalues[0])
    crossing = 0.9 + 0.2 * lowest[0] / (lowest[0] - lowest[1])
    assert crossing == pytest.approx(1.0, abs=3e-3)


def test_free_free_beam_bending_eigenvalues():
    """Free–free beam of unit mass per length: lambda = B (beta/L)^4, beta = 4.7300, 7.8532;
    the six rigid motions are removed; B2 = 2 B1 separates the two bending planes."""
    n = 81
    s = np.linspace(0, LENGTH, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=B,
        bending_stiffness2=2 * B,
        twist_stiffness=B / 1.3,
        axial_stiffness=100 * E * np.pi * RADIUS**2,
    )
    res = stability(model, count=4)
    assert res.rigid_modes == 6 and res.stable
    unit = B * (4.730040745 / LENGTH) ** 4
    expected = np.array(
        [1.0, 2.0, (7.853204624 / 4.730040745) ** 4, 2 * (7.853204624 / 4.730040745) ** 4]
    )
    np.testing.assert_allclose(res.eigenvalues / unit, expected, rtol=4e-3)
    # the first mode bends toward m1 = +z (B1) and is symmetric about the middle
    mode = res.modes.displacements[0]
    assert np.abs(mode[:, 2]).max() > 100 * np.abs(mode[:, 1]).max()
    np.testing.assert_allclose(mode[:, 2], mode[::-1, 2], atol=1e-8 * np.abs(mode).max())


def test_stability_rejects_a_bad_count():
    with pytest.raises(InvalidParameterError, match="count"):
        stability(column(5), count=-1)
    with pytest.raises(InvalidParameterError, match="count"):
        stability(column(5), count=1.5)  # type: ignore[arg-type]


@pytest.mark.parametrize("factor", [0.8, 1.2])
def test_stability_verdict_only_computes_the_mode_when_unstable(factor):
    # count=0: one Cholesky factorization decides a stable state (no eigenvalue, no mode); an
    # unstable one gets its lowest eigenvalue and mode, the same as count=1 gives
    n = 41
    model, supports = column(n), Supports.clamp_ends(n)
    loads = Loads(forces=[(n - 1, (-factor * P_CR, 0.0, 0.0))])
    straight = solve_static(model, supports, loads, options=NewtonOptions(check_stability=False))
    quick = stability(model, straight.state, supports, loads, count=0)
    full = stability(model, straight.state, supports, loads, count=1)
    assert quick.stable == full.stable == (factor < 1)
    if factor < 1:
        assert quick.certificate == "cholesky" and len(quick.eigenvalues) == 0
        assert quick.modes.count == 0
    else:
        assert quick.eigenvalues[0] == pytest.approx(full.eigenvalues[0], rel=1e-8)
        assert quick.eigenvalues[0] < 0 and quick.modes.count == 1
        np.testing.assert_allclose(
            np.abs(quick.modes.displacements[0]), np.abs(full.modes.displacements[0]), atol=1e-8
        )


def test_stability_docstring_example_runs():
    failures = doctest.testmod(stability_module, verbose=False).failed
    assert failures == 0


def test_rosenbrock_minimum_is_certified_with_its_eigenvalues():
    obj = FunctionObjective(rosen, rosen_der, rosen_hess)
    res = minimize(obj, np.array([-1.2, 1.0]))
    assert res.converged and res.stable and res.escapes == 0
    np.testing.assert_allclose(
        res.eigenvalues, np.linalg.eigvalsh(rosen_hess(np.ones(2))), rtol=1e-6
    )


def _saddle_objective() -> FunctionObjective:
    """f = x^2 - y^2 + y^4: a saddle at the origin, minima at (0, +-1/sqrt 2)."""
    return FunctionObjective(
        lambda v: v[0] ** 2 - v[1] ** 2 + v[1] ** 4,
        lambda v: np.array([2 * v[0], -2 * v[1] + 4 * v[1] ** 3]),
        lambda v: np.diag([2.0, -2.0 + 12 * v[1] ** 2]),
    )


def test_a_saddle_reached_exactly_is_left_along_negative_curvature():
    res = minimize(_saddle_objective(), np.array([0.5, 0.0]))
    assert res.converged and res.stable and res.escapes == 1
    np.testing.assert_allclose(np.abs(res.x), [0.0, 1 / np.sqrt(2)], atol=1e-9)
    # without the check the solver never leaves the saddle's line y = 0
    plain = minimize(
        _saddle_objective(), np.array([0.5, 0.0]), NewtonOptions(check_stability=False)
    )
    assert plain.stable is None and abs(plain.x[1]) == 0.0


def test_an_unleavable_saddle_is_reported_not_converged():
    res = minimize(_saddle_objective(), np.array([0.5, 0.0]), NewtonOptions(saddle_escapes=0))
    assert res.status is Status.SADDLE and not res.converged


class _MaskedSaddle(FunctionObjective):
    """f = x^2/2 - eps y^2/2 + y^4/4 with the convex approximation diag(1, 1): the exact
    Hessian is indefinite near y = 0, and whole steps on the convex one grow y only by a
    factor 1 + eps per iteration (the iterate creeps off the saddle, the residual growing)."""

    eps = 0.05

    def __init__(self) -> None:
        e = self.eps
        super().__init__(
            lambda v: 0.5 * v[0] ** 2 - 0.5 * e * v[1] ** 2 + 0.25 * v[1] ** 4,
            lambda v: np.array([v[0], -e * v[1] + v[1] ** 3]),
            lambda v: np.diag([1.0, -e + 3 * v[1] ** 2]),
            energy_scale=1e-12,
        )
        self.has_convex_hessian = True

    def evaluate(self, x, need_grad, need_hess):  # type: ignore[no-untyped-def]
        f, g, h = super().evaluate(x, need_grad, need_hess)
        return f, g, (np.eye(2) if need_hess == 2 else h)

    def convex_hessian(self, x):  # type: ignore[no-untyped-def]
        return np.eye(2)


def test_creeping_off_a_masked_saddle_is_extended():
    # from y = 1e-4 the creep needs ln(sqrt(eps) / 1e-4) / eps ~ 150 whole steps
    start = np.array([0.0, 1e-4])
    res = minimize(_MaskedSaddle(), start)
    plain = minimize(_MaskedSaddle(), start, NewtonOptions(creep_steps=0))
    assert res.converged and res.stable and plain.converged
    assert res.iterations < 80 < 140 < plain.iterations
    assert res.history[:, 2].max() > 1.0  # extended whole steps
    # along the ray the creep follows: the same minimum, on the same side
    np.testing.assert_allclose(res.x, [0.0, np.sqrt(_MaskedSaddle.eps)], atol=1e-9)
    np.testing.assert_allclose(res.x, plain.x, atol=1e-9)
    with pytest.raises(InvalidParameterError, match="creep_steps"):
        NewtonOptions(creep_steps=-1)


def test_decrement_exit_does_not_accept_a_residual_above_rtol():
    """Flat energy, constant gradient 1e-8 (a round-off floor): the Newton decrement is tiny,
    but the residual is 10x rtol; the old exit reported CONVERGED here."""
    obj = FunctionObjective(lambda v: 0.0, lambda v: np.full(2, 1e-8), lambda v: np.eye(2))
    res = minimize(obj, np.zeros(2), NewtonOptions(rtol=1e-9))
    assert res.status is Status.STALLED and not res.converged and res.residual > 1e-9
    assert minimize(obj, np.zeros(2), NewtonOptions(rtol=1e-7)).converged


def test_a_stiff_rod_converges_at_its_round_off_floor():
    """EA / (B / L^2) = 1e8 at 10 mm from the origin: the residual cannot go below ~6e-9 of
    the force scale in double precision; the objective's floor estimate lets the solve end
    there (reported), where the old decrement exit accepted up to 1e3 x rtol blindly."""
    n = 41
    s = np.linspace(0, LENGTH, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=1e-2,
        bending_stiffness2=1e-2,
        twist_stiffness=1e-2,
        axial_stiffness=1e4,
    )
    obj = RodObjective(
        model,
        model.reference_state(),
        Supports.clamp_ends(n),
        Loads(forces=[(n - 1, (-1e-3, 0, 0))]),
    )
    res = minimize(obj, obj.vector())
    assert res.converged and res.stable
    assert res.residual_floor > 1e-9  # above the default rtol
    assert res.residual <= res.residual_floor


def test_modes_are_kept_when_asked_and_are_node_fields():
    n = 21
    res = solve_static(
        column(n),
        Supports.clamp_ends(n),
        Loads(forces=[(n - 1, (-0.5 * P_CR, 0.0, 0.0))]),
        options=NewtonOptions(eigenvalues=2, keep_modes=True),
    )
    assert res.stable and res.modes is not None and res.modes.count == 2
    assert res.modes.displacements.shape == (2, n, 3) and res.modes.twist.shape == (2, n - 1)
    # the clamped first edge does not move; the tip moves most (first bending mode)
    d = np.linalg.norm(res.modes.displacements[0], axis=1)
    assert d[:2].max() == 0.0 and np.argmax(d) == n - 1
    assert solve_static(column(n)).modes is None  # not kept by default
