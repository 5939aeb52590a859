"""Rigid motions are removed from the stability test only where nothing acts on them.

A free rod under self-equilibrated compressive dead loads is unstable: turning it rigidly
lowers the loads' potential (a half turn puts it in tension). At an equilibrium the curvature
of the energy along the rigid rotation ``w x r`` is the loads' second variation
``-sum_i f_i . (w x (w x r_i)) = -P L`` per unit angle squared, so its Rayleigh quotient in the
solver's metric is ``-P L / I`` with ``I = sum_i M_i (x_i - x_c)^2`` (exact), and the lowest
eigenvalue of the coupled problem lies below it (Rayleigh). In tension the same directions are
stiffened (``+P L / I``) and stay in the test, with a positive eigenvalue.
"""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.rod.model import Model
from rotomorph.solve import spectrum
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.spectrum import DENSE_LIMIT, analyse_hessian
from rotomorph.solve.stability import stability
from rotomorph.solve.static import solve_static

B, L, N = 0.01, 10.0, 41  # N mm², mm, nodes
P_E = np.pi**2 * B / L**2  # Euler load of the pinned-pinned rod (N)


def _rod() -> Model:
    s = np.linspace(0.0, L, N)
    return Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=B,
        bending_stiffness2=B,
        twist_stiffness=B / 1.3,
        axial_stiffness=10.0,
    )


def _loaded(factor: float):  # type: ignore[no-untyped-def]
    """The straight free rod under end forces ``factor P_E`` pointing inward (compression;
    negative: tension), solved without the stability check (straight by symmetry)."""
    model = _rod()
    p = factor * P_E
    loads = Loads(forces=[(0, (p, 0.0, 0.0)), (N - 1, (-p, 0.0, 0.0))])
    res = solve_static(model, loads=loads, options=NewtonOptions(check_stability=False))
    return model, loads, res.state, p


def _rotation_quotient(model: Model, loads: Loads, state, p: float) -> float:  # type: ignore[no-untyped-def]
    """``-P L / I``: the loads' exact curvature along the rigid rotation about z, per unit
    metric norm (L the loaded rod's length, I its metric moment of inertia)."""
    obj = RodObjective(model, state, Supports(), loads)
    m = obj._node_metric
    x = state.positions[:, 0]
    inertia = float(np.sum(m * (x - m @ x / m.sum()) ** 2))
    return -p * float(x[-1] - x[0]) / inertia


@pytest.mark.parametrize("factor", [0.1, 0.5])
def test_free_rod_under_compressive_dead_loads_is_unstable(factor):
    model, loads, state, p = _loaded(factor)
    res = stability(model, state, Supports(), loads, count=3)
    quotient = _rotation_quotient(model, loads, state, p)
    assert not res.stable
    assert res.rigid_modes == 4  # three translations and the turn about the rod's own axis
    # two rotations (about y and z) lower the energy: both eigenvalues lie below their
    # Rayleigh quotient and within the coupling to bending (a few %) of it
    assert res.eigenvalues[0] <= res.eigenvalues[1] < 0 < res.eigenvalues[2]
    for lam in res.eigenvalues[:2]:
        assert quotient * 1.08 < lam <= quotient * (1 - 1e-9)
    # the unstable mode is a rigid turn: lateral motion linear along the rod
    mode = res.modes.displacements[0]
    lateral = np.hypot(mode[:, 1], mode[:, 2])
    s = state.positions[:, 0] - state.positions[:, 0].mean()
    assert np.corrcoef(np.abs(s), lateral)[0, 1] > 0.99


def test_free_rod_in_tension_keeps_the_stiffened_rotations_in_the_test():
    model, loads, state, p = _loaded(-0.5)
    res = stability(model, state, Supports(), loads, count=3)
    quotient = _rotation_quotient(model, loads, state, p)
    assert res.stable and res.rigid_modes == 4
    assert quotient > 0
    for lam in res.eigenvalues[:2]:
        assert 0.95 * quotient < lam <= quotient * (1 + 1e-9)


def test_free_rod_without_load_removes_all_six_rigid_motions():
    model = _rod()
    res = stability(model, count=2)
    assert res.stable and res.rigid_modes == 6
    assert res.eigenvalues[0] == pytest.approx(B * (4.7300 / L) ** 4, rel=0.01)
    verdict = stability(model, count=0)
    assert verdict.stable and verdict.certificate == "cholesky" and verdict.rigid_modes == 6


def test_compressed_free_rod_is_not_certified_by_cholesky():
    model, loads, state, _ = _loaded(0.1)
    res = stability(model, state, Supports(), loads, count=0)
    assert not res.stable and res.certificate == "eigenvalues"


def _pencil_with_rigid_direction(rng: np.random.Generator, n: int, curvature: float):
    """Positive definite ``H`` on the complement of a direction ``r`` that is an exact
    eigenvector of curvature ``curvature`` (a rigid motion a load turns), metric ``M``; the
    spectrum of the rest spreads over eight decades, as a lattice's does (seven)."""
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    H = (Q * np.geomspace(1e-6, 1e2, n)) @ Q.T
    M = rng.uniform(0.5, 2.0, n)
    r = rng.normal(size=n)
    r /= np.sqrt(r @ (M * r))
    P = np.eye(n) - np.outer(r, M * r)
    Mr = M * r
    return P.T @ (0.5 * (H + H.T)) @ P + curvature * np.outer(Mr, Mr), M, r[:, None]


@pytest.mark.parametrize("dense", [True, False])
def test_negative_rigid_curvature_below_the_old_band_is_unstable(rng, monkeypatch, dense):
    """A curvature of 1e-6 of the diagonal scale was removed as "rigid" before; it is ten
    times the lowest eigenvalue of the rest here, and the point is unstable with it as its
    lowest eigenvalue (exact: ``r`` is an eigenvector)."""
    n = DENSE_LIMIT + 60
    if dense:
        monkeypatch.setattr(spectrum, "DENSE_LIMIT", n)
    H, M, r = _pencil_with_rigid_direction(rng, n, 0.0)
    scale = float(np.max(np.diag(H) / M))
    rest = analyse_hessian(H, M, r, count=1).eigenvalues[0]
    curvature = -10 * rest
    assert abs(curvature) < 1e-6 * scale  # inside the band of the old test
    Mr = M * r[:, 0]
    H = H + curvature * np.outer(Mr, Mr)
    for count in (0, 2):
        spec = analyse_hessian(H, M, r, count=count)
        assert not spec.stable and spec.rigid == 0
        assert spec.eigenvalues[0] == pytest.approx(curvature, rel=1e-8)
        mode = spec.negative_mode()
        assert mode is not None
        assert abs(mode @ (M * r[:, 0])) == pytest.approx(1.0, rel=1e-8)


def test_null_rigid_direction_is_removed_and_cholesky_certifies(rng):
    n = DENSE_LIMIT + 60
    H, M, r = _pencil_with_rigid_direction(rng, n, 0.0)
    rest = analyse_hessian(H, M, r, count=1).eigenvalues[0]
    for curvature in (0.0, 1e-5 * rest, -1e-5 * rest):
        Mr = M * r[:, 0]
        Hc = H + curvature * np.outer(Mr, Mr)
        verdict = analyse_hessian(Hc, M, r, count=0)
        assert verdict.stable and verdict.certificate == "cholesky" and verdict.rigid == 1
        spec = analyse_hessian(Hc, M, r, count=2)
        assert spec.stable and spec.rigid == 1
        assert spec.eigenvalues[0] == pytest.approx(rest, rel=1e-8)


def test_symmetry_action_is_what_the_hessian_shows_along_rigid_motions_off_equilibrium():
    """Away from an equilibrium ``H (w x r) = w x grad E`` (differentiated invariance), so a
    bent, unloaded rod that is not in equilibrium still has all six rigid motions removed.
    (Bent in a plane, the isotropic rod has no twist moment: the twist angles' reference
    frames are carried by parallel transport, which a rigid rotation turns only to first
    order, so the identity holds to round-off where the twist gradient vanishes.)"""
    from dataclasses import replace

    from rotomorph.solve.stability import symmetry_action

    model = _rod()
    state = model.reference_state()
    x = state.positions.copy()
    s = x[:, 0] / L
    x[:, 1] = 0.4 * np.sin(np.pi * s)
    t = np.diff(x, axis=0)
    t /= np.linalg.norm(t, axis=1, keepdims=True)
    d1 = state.directors - np.sum(state.directors * t, axis=1, keepdims=True) * t
    d1 /= np.linalg.norm(d1, axis=1, keepdims=True)
    bent = replace(state, positions=x, tangents=t, directors=d1)
    obj = RodObjective(model, bent, Supports(), Loads())
    _, g, H = obj.evaluate(obj.vector(), True, 1)
    R = obj.rigid_modes()
    HR = np.column_stack([spectrum.matvec(H, np.ascontiguousarray(c)) for c in R.T])
    act = symmetry_action(obj, R, g)
    assert np.linalg.norm(g) > 1e-3  # far from an equilibrium
    assert np.linalg.norm(act[:, 3:]) > 1e-3 * np.linalg.norm(g)  # rotations see it
    assert np.abs(HR - act).max() < 1e-9 * np.abs(HR).max()
    assert np.abs(act[:, :3]).max() < 1e-12 * np.abs(act).max()  # translations: nothing
    res = stability(model, bent, count=2)
    assert res.rigid_modes == 6
    # without the symmetry's action the straight rotations look curved: not all removed
    raw = analyse_hessian(H, obj.metric(), R, count=2)
    assert raw.rigid < 6
