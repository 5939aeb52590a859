r"""Shift-invert Lanczos for the lowest eigenvalues of a symmetric pencil, stopping when converged.

For ``H v = lambda M v`` (``M`` diagonal, positive) and a shift ``sigma`` below the lowest
eigenvalue, the operator ``S = (H - sigma M)^{-1} M`` is self-adjoint in the ``M`` inner product
with eigenvalues ``theta = 1 / (lambda - sigma) > 0``; the lowest ``lambda`` are its largest
``theta``, well separated, so Lanczos finds them in a few steps (Ericsson & Ruhe, *Math. Comp.*
35, 1980). Each step applies ``S`` once (one solve with a factor of ``H - sigma M``), and the
basis is kept ``M``-orthonormal by full reorthogonalisation (twice, Parlett, *The Symmetric
Eigenvalue Problem*, 1998, §6.9), so no spurious copies appear. The iteration stops as soon as
each wanted Ritz value's residual estimate ``|beta_j s_j|`` is within ``tol`` of it, the test
ARPACK applies (Lehoucq, Sorensen & Yang, *ARPACK Users' Guide*, SIAM 1998, §4.6), but checked
at every step instead of after a fixed basis size.

The steps themselves (one solve, the projection, the recurrence and both
reorthogonalisation passes) can run compiled, in one call between convergence tests
(:func:`banded_steps`, :func:`supernodal_steps`): at a few hundred unknowns a step's
twenty-odd small NumPy calls cost several times its solve. The compiled steps do the same
operations in the same order; only the order of the sums inside each inner product differs, so
the Ritz values agree to round-off.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
from numba import njit

from rotomorph._typing import FloatArray, IntArray
from rotomorph.solve.banded import banded_cholesky_solve
from rotomorph.solve.supernodal import solve_numeric

__all__ = ["Steps", "banded_steps", "shift_invert_lanczos", "supernodal_steps"]

#: ``steps(basis, alpha, beta, j0, j1) -> j``: Lanczos steps ``j0`` to ``j1 - 1`` done in place,
#: stopping early after a step whose ``beta`` is not positive; returns the last step done
Steps = Callable[[FloatArray, FloatArray, FloatArray, int, int], int]


def shift_invert_lanczos(
    apply: Callable[[FloatArray], FloatArray],
    M: FloatArray,
    v0: FloatArray,
    count: int,
    *,
    tol: float = 1e-10,
    min_steps: int = 0,
    max_steps: int = 120,
    steps_kernel: Steps | None = None,
) -> tuple[FloatArray, FloatArray] | None:
    """The ``count`` largest eigenvalues ``theta`` of ``S = apply(M x)`` and their vectors.

    Parameters
    ----------
    apply
        ``b -> (H - sigma M)^{-1} b`` (with any projection that keeps ``S`` ``M``-self-adjoint).
    M
        Positive diagonal of the metric ``(n,)``.
    v0
        Start vector ``(n,)`` (not ``M``-orthogonal to the wanted vectors).
    count
        How many of the largest ``theta`` are wanted.
    tol
        Relative residual at which a Ritz value is accepted.
    min_steps
        Smallest basis at which convergence is tested. From one start vector Lanczos meets a
        repeated eigenvalue once in exact arithmetic and its second copy only through round-off,
        a few steps later: with ``count > 1`` a basis as large as ARPACK's default
        (``max(2 count + 1, 20)``) gives the copies that time.
    max_steps
        Largest basis; None is returned when the wanted values have not converged by then (or
        the start vector spans fewer than ``count`` directions).
    steps_kernel
        The same steps compiled (:func:`banded_steps`, :func:`supernodal_steps`), run in one
        call up to each convergence test; ``apply`` is then not called.

    Returns
    -------
    theta, vectors
        Ascending ``(count,)`` and the matching ``M``-orthonormal Ritz vectors ``(n, count)``.
    """
    n = len(M)
    steps = min(n, max_steps)
    basis = np.empty((steps + 1, n))
    alpha = np.empty(steps)
    beta = np.empty(steps)
    q = np.asarray(v0, dtype=float)
    norm = np.sqrt(q @ (M * q))
    if not norm > 0.0:
        return None
    basis[0] = q / norm
    first = max(count, min(min_steps, steps))  # the first basis size that is tested
    j = 0
    while j < steps:
        if steps_kernel is not None:
            # every step up to the next test in one compiled call; j: the last step done
            j = steps_kernel(basis, alpha, beta, j, max(j + 1, min(first, steps)))
        else:
            w = apply(M * basis[j])
            alpha[j] = basis[j] @ (M * w)
            w = w - alpha[j] * basis[j]
            if j:
                w -= beta[j - 1] * basis[j - 1]
            for _ in range(2):
                w -= (basis[: j + 1] @ (M * w)) @ basis[: j + 1]
            beta[j] = np.sqrt(w @ (M * w))
            if beta[j] > 0.0:
                basis[j + 1] = w / beta[j]
        m = j + 1
        if m >= first:
            theta, s = sla.eigh_tridiagonal(alpha[:m], beta[: m - 1])
            top = slice(m - count, m)
            residual = np.abs(beta[j] * s[-1, top])
            exhausted = not beta[j] > 1e-14 * np.max(np.abs(theta))
            if exhausted or np.all(residual <= tol * np.abs(theta[top])):
                return theta[top], basis[:m].T @ s[:, top]
        if not beta[j] > 0.0:
            return None
        j += 1
    return None


@njit(cache=True)
def _rhs(M, v, R, RM):  # pragma: no cover - compiled
    """``b = M v`` with the rigid loads removed, ``b - RM^T (R^T b)``."""
    b = M * v
    _subtract_low_rank(b, R, RM)
    return b


@njit(cache=True)
def _subtract_low_rank(x, U, V):  # pragma: no cover - compiled
    """``x -= V^T (U^T x)`` in place, for ``U`` of shape (n, k) and ``V`` of shape (k, n)."""
    n, k = U.shape
    if k:
        c = np.zeros(k)
        for i in range(n):
            for a in range(k):
                c[a] += U[i, a] * x[i]
        for i in range(n):
            s = 0.0
            for a in range(k):
                s += V[a, i] * c[a]
            x[i] -= s


@njit(cache=True)
def _recurrence(w, M, R, RM, basis, alpha, beta, j):  # pragma: no cover - compiled
    """Step ``j`` after its solve ``w``: projection, three-term recurrence, two passes of
    full reorthogonalisation, ``beta[j]`` and the next basis vector; False if ``beta[j]`` is
    not positive."""
    n = R.shape[0]
    _subtract_low_rank(w, RM.T, R.T)  # the M-orthogonal projector I - R R^T M
    q = basis[j]
    a_j = 0.0
    for i in range(n):
        a_j += q[i] * (M[i] * w[i])
    alpha[j] = a_j
    for i in range(n):
        w[i] -= a_j * q[i]
    if j:
        p = basis[j - 1]
        bp = beta[j - 1]
        for i in range(n):
            w[i] -= bp * p[i]
    h = np.empty(j + 1)
    for _ in range(2):
        for r in range(j + 1):
            s = 0.0
            row = basis[r]
            for i in range(n):
                s += row[i] * (M[i] * w[i])
            h[r] = s
        for r in range(j + 1):
            row = basis[r]
            hr = h[r]
            for i in range(n):
                w[i] -= hr * row[i]
    s = 0.0
    for i in range(n):
        s += w[i] * (M[i] * w[i])
    beta[j] = np.sqrt(s)
    if not beta[j] > 0.0:
        return False
    nxt = basis[j + 1]
    for i in range(n):
        nxt[i] = w[i] / beta[j]
    return True


@njit(cache=True)
def _banded_steps(c, u, M, R, RM, basis, alpha, beta, j0, j1):  # pragma: no cover - compiled
    for j in range(j0, j1):
        w = banded_cholesky_solve(c, u, _rhs(M, basis[j], R, RM))
        if not _recurrence(w, M, R, RM, basis, alpha, beta, j):
            return j
    return j1 - 1


@njit(cache=True)
def _supernodal_steps(
    first, rp, ri, px, lx, perm, M, R, RM, basis, alpha, beta, j0, j1
):  # pragma: no cover - compiled
    for j in range(j0, j1):
        w = solve_numeric(first, rp, ri, px, lx, perm, _rhs(M, basis[j], R, RM))
        if not _recurrence(w, M, R, RM, basis, alpha, beta, j):
            return j
    return j1 - 1


def banded_steps(c: FloatArray, u: int, M: FloatArray, R: FloatArray) -> Steps:
    """Compiled steps of ``S = P (H - sigma M)^{-1} P^T M`` with the banded Cholesky factor
    ``c`` (upper, half-bandwidth ``u``) of ``H - sigma M`` and the ``M``-orthogonal projector
    ``P = I - R R^T M`` off the ``M``-orthonormal columns ``R`` ``(n, k)``."""
    R = np.ascontiguousarray(R, dtype=float)
    RM = np.ascontiguousarray((M[:, None] * R).T)
    return lambda basis, alpha, beta, j0, j1: int(
        _banded_steps(c, u, M, R, RM, basis, alpha, beta, j0, j1)
    )


def supernodal_steps(
    structure: tuple[IntArray, ...],
    lx: FloatArray,
    perm: IntArray,
    M: FloatArray,
    R: FloatArray,
) -> Steps:
    """As :func:`banded_steps` with a supernodal factor (``structure = (first, rp, ri, px)``
    and values ``lx`` of :mod:`rotomorph.solve.supernodal`, ordering ``perm``)."""
    R = np.ascontiguousarray(R, dtype=float)
    RM = np.ascontiguousarray((M[:, None] * R).T)
    first, rp, ri, px = structure
    return lambda basis, alpha, beta, j0, j1: int(
        _supernodal_steps(first, rp, ri, px, lx, perm, M, R, RM, basis, alpha, beta, j0, j1)
    )
