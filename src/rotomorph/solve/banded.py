"""Compiled Cholesky factorization and solve of symmetric positive definite banded matrices.

Upper banded storage as in LAPACK: ``ab[u + i - j, j] = A[i, j]`` for ``j - u <= i <= j``.
The factorization ``A = U^T U`` is the textbook banded Cholesky (Golub & Van Loan, *Matrix
Computations*, 4th ed., Alg. 4.3.5), ``n u^2 / 2`` multiply-adds, written out in a compiled loop:
at the half-bandwidth of a discrete rod (10), LAPACK's ``dpbtrf`` spends most of its time in
per-column BLAS calls. A non-positive pivot reports "not positive definite", which is what a
modified-Newton method needs.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph._typing import FloatArray


@njit(cache=True)
def banded_cholesky(ab: FloatArray, u: int) -> bool:  # pragma: no cover - compiled
    """Factor in place (``ab`` becomes ``U``); False if a pivot is not positive."""
    n = ab.shape[1]
    inv = np.empty(n)
    for j in range(n):
        i0 = max(0, j - u)
        d = ab[u, j]
        for i in range(i0, j):
            s = ab[u + i - j, j]
            for k in range(i0, i):
                s -= ab[u + k - i, i] * ab[u + k - j, j]
            s *= inv[i]
            ab[u + i - j, j] = s
            d -= s * s
        if not d > 0.0:
            return False
        d = np.sqrt(d)
        ab[u, j] = d
        inv[j] = 1.0 / d
    return True


@njit(cache=True)
def banded_cholesky_solve(c: FloatArray, u: int, b: FloatArray) -> FloatArray:  # pragma: no cover
    """Solve ``U^T U x = b`` with the factor from :func:`banded_cholesky`."""
    n = c.shape[1]
    x = b.copy()
    for j in range(n):
        s = x[j]
        for i in range(max(0, j - u), j):
            s -= c[u + i - j, j] * x[i]
        x[j] = s / c[u, j]
    for i in range(n - 1, -1, -1):
        s = x[i]
        for j in range(i + 1, min(n, i + u + 1)):
            s -= c[u + i - j, j] * x[j]
        x[i] = s / c[u, i]
    return x


@njit(cache=True)
def shifted_banded_solve(ab, u, shift, rhs, work):  # pragma: no cover - compiled
    """Copy ``ab`` into ``work``, add ``shift`` to the diagonal, factor and solve.

    Returns ``(ok, x)``; ``x`` is meaningless when ``ok`` is False.
    """
    for r in range(ab.shape[0]):
        for c in range(ab.shape[1]):
            work[r, c] = ab[r, c]
    for c in range(ab.shape[1]):
        work[u, c] += shift[c]
    if not banded_cholesky(work, u):
        return False, rhs
    return True, banded_cholesky_solve(work, u, rhs)
