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
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla

from rotomorph._typing import FloatArray

__all__ = ["shift_invert_lanczos"]


def shift_invert_lanczos(
    apply: Callable[[FloatArray], FloatArray],
    M: FloatArray,
    v0: FloatArray,
    count: int,
    *,
    tol: float = 1e-10,
    min_steps: int = 0,
    max_steps: int = 120,
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
    for j in range(steps):
        w = apply(M * basis[j])
        alpha[j] = basis[j] @ (M * w)
        w = w - alpha[j] * basis[j]
        if j:
            w -= beta[j - 1] * basis[j - 1]
        for _ in range(2):
            w -= (basis[: j + 1] @ (M * w)) @ basis[: j + 1]
        beta[j] = np.sqrt(w @ (M * w))
        m = j + 1
        if m >= max(count, min(min_steps, steps)):
            theta, s = sla.eigh_tridiagonal(alpha[:m], beta[: m - 1])
            top = slice(m - count, m)
            residual = np.abs(beta[j] * s[-1, top])
            exhausted = not beta[j] > 1e-14 * np.max(np.abs(theta))
            if exhausted or np.all(residual <= tol * np.abs(theta[top])):
                return theta[top], basis[:m].T @ s[:, top]
        if not beta[j] > 0.0:
            return None
        basis[j + 1] = w / beta[j]
    return None
