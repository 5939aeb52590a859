"""Shift-invert Lanczos against dense eigensolvers, and the sparse certificate built on it."""

from __future__ import annotations

import numpy as np
import scipy.linalg as sla

from rotomorph.solve import spectrum
from rotomorph.solve.lanczos import shift_invert_lanczos
from rotomorph.solve.spectrum import DENSE_LIMIT, analyse_hessian


def _pencil(rng: np.random.Generator, n: int) -> tuple[np.ndarray, np.ndarray]:
    """A random symmetric positive definite ``H`` with a spread spectrum and a diagonal ``M``."""
    Q = np.linalg.qr(rng.normal(size=(n, n)))[0]
    H = (Q * np.geomspace(1e-3, 1e2, n)) @ Q.T
    return 0.5 * (H + H.T), rng.uniform(0.5, 2.0, n)


def test_lanczos_finds_the_lowest_eigenpairs_of_the_pencil(rng):
    H, M = _pencil(rng, 200)
    sigma = -1e-4
    chol = sla.cho_factor(H - sigma * np.diag(M))
    found = shift_invert_lanczos(
        lambda b: sla.cho_solve(chol, b), M, np.cos(np.arange(200.0)), 3, max_steps=200
    )
    assert found is not None
    theta, vec = found
    lam, V = sla.eigh(H, np.diag(M), subset_by_index=[0, 2])
    np.testing.assert_allclose(sigma + 1.0 / theta[::-1], lam, rtol=1e-10)
    np.testing.assert_allclose(vec.T @ (M[:, None] * vec), np.eye(3), atol=1e-10)
    for j in range(3):  # the same eigenvectors up to sign (eigh's are M-orthonormal)
        assert abs(abs(vec[:, 2 - j] @ (M * V[:, j])) - 1.0) < 1e-8


def test_lanczos_reports_no_convergence_within_its_basis(rng):
    H, M = _pencil(rng, 200)
    chol = sla.cho_factor(H)
    solve = lambda b: sla.cho_solve(chol, b)  # noqa: E731
    assert shift_invert_lanczos(solve, M, np.ones(200), 3, max_steps=3) is None
    assert shift_invert_lanczos(solve, M, np.zeros(200), 1) is None


def _with_soft_rigid_mode(rng: np.random.Generator, n: int, curvature: float):
    """``H`` that annihilates a direction ``r`` up to a Rayleigh quotient ``curvature``."""
    H, M = _pencil(rng, n)
    r = rng.normal(size=n)
    r /= np.sqrt(r @ (M * r))
    P = np.eye(n) - np.outer(r, M * r)  # M-orthogonal projector off r
    Mr = M * r
    return P.T @ H @ P + curvature * np.outer(Mr, Mr), M, r[:, None]


def test_sparse_certificate_matches_dense_and_skips_hopeless_shifts(rng, monkeypatch):
    n = DENSE_LIMIT + 60
    H, M, r = _with_soft_rigid_mode(rng, n, -1e-9 * 1e2)
    scale = float(np.max(np.diag(H) / M))
    spec = analyse_hessian(H, M, r, count=2)
    assert spec.rigid == 1 and spec.stable
    # dense reference on the M-orthogonal complement of r
    monkeypatch.setattr(spectrum, "DENSE_LIMIT", n)
    dense = analyse_hessian(H, M, r, count=2)
    np.testing.assert_allclose(spec.eigenvalues, dense.eigenvalues, rtol=1e-9)
    # the soft rigid direction (Rayleigh quotient -1e-7, within 1e-3 of the lowest eigenvalue
    # of the rest: null) rules out the shifts -1e-14 ... -1e-9 scale: one factorization
    # instead of seven
    assert 1e-7 < spectrum.NULL_TOL * spec.eigenvalues[0] and -1e-7 < -1e-9 * scale
    assert spec.factorizations == 1
    R = spectrum._rigid_directions(H, M, r).basis
    lam, _, tried = spectrum._sparse_eigen(H, M, R, 2, scale, False, 1e-12)  # no bound given
    assert tried > 1
    np.testing.assert_allclose(lam, spec.eigenvalues, rtol=1e-9)


def test_sparse_certificate_falls_back_to_arpack(rng, monkeypatch):
    n = DENSE_LIMIT + 60
    H, M, r = _with_soft_rigid_mode(rng, n, 0.0)
    H -= 2e-3 * np.diag(M)  # unstable: the lowest eigenvalue of the complement is negative
    spec = analyse_hessian(H, M, r, count=2)
    monkeypatch.setattr(spectrum, "shift_invert_lanczos", lambda *a, **k: None)
    arpack = analyse_hessian(H, M, r, count=2)
    assert not spec.stable and not arpack.stable
    np.testing.assert_allclose(spec.eigenvalues, arpack.eigenvalues, rtol=1e-8)
    mode, other = spec.negative_mode(), arpack.negative_mode()
    assert mode is not None and other is not None
    np.testing.assert_allclose(mode, other, atol=1e-6 * np.abs(other).max())
