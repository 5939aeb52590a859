"""Factorizations of symmetric matrices that report positive definiteness.

Modified Newton needs to know whether ``H + shift * M`` is positive definite. Banded matrices
(single rods) use a compiled banded Cholesky (:mod:`rotomorph.solve.banded`), which fails on a
non-positive pivot.
General sparse matrices (networks) use SuperLU in symmetric mode with a symmetric fill-reducing
ordering and no pivoting (``diag_pivot_thresh = 0``): then ``P A P^T = L U`` with
``U = D L^T``, so by Sylvester's law of inertia ``A`` is positive definite exactly when every
diagonal entry of ``U`` is positive.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg import lapack

from rotomorph._typing import FloatArray
from rotomorph.solve.banded import shifted_banded_solve


@dataclass(frozen=True, eq=False)
class BandedMatrix:
    """Symmetric matrix in LAPACK upper banded storage ``ab[u + i - j, j] = A[i, j]``."""

    ab: FloatArray
    u: int

    @property
    def n(self) -> int:
        """Matrix size."""
        return self.ab.shape[1]

    @property
    def diagonal(self) -> FloatArray:
        """Main diagonal."""
        return self.ab[self.u]

    def to_dense(self) -> FloatArray:
        """Dense copy (for tests)."""
        n, u = self.n, self.u
        out = np.zeros((n, n))
        for k in range(u + 1):
            d = self.ab[u - k, k:]
            out[np.arange(n - k), np.arange(k, n)] = d
            out[np.arange(k, n), np.arange(n - k)] = d
        return out


def solve_shifted(
    H: BandedMatrix | sp.csc_matrix | FloatArray, rhs: FloatArray, shift: FloatArray
) -> FloatArray | None:
    """Solve ``(H + diag(shift)) x = rhs`` if the shifted matrix is positive definite.

    Returns
    -------
    ndarray or None
        The solution, or ``None`` when the shifted matrix is not positive definite.
    """
    if isinstance(H, BandedMatrix):
        ok, x = shifted_banded_solve(H.ab, H.u, shift, rhs, np.empty_like(H.ab))
        return x if ok else None
    if sp.issparse(H):
        A = (H + sp.diags(shift)).tocsc()
        try:
            lu = spla.splu(
                A,
                permc_spec="MMD_AT_PLUS_A",
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError:  # exactly singular
            return None
        if not (np.all(np.isfinite(lu.U.diagonal())) and np.all(lu.U.diagonal() > 0)):
            return None
        # a row interchange would invalidate the inertia argument
        if not np.array_equal(lu.perm_r, lu.perm_c):
            return None
        return lu.solve(rhs)
    A = np.asarray(H) + np.diag(shift)
    c, info = lapack.dpotrf(A, lower=0)
    if info != 0:
        return None
    x, info = lapack.dpotrs(c, rhs, lower=0)
    return x if info == 0 else None
