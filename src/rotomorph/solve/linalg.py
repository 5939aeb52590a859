"""Factorizations of symmetric matrices that report positive definiteness.

Modified Newton needs to know whether ``H + diag(shift)`` is positive definite. Banded matrices
(single rods) use a compiled banded Cholesky (:mod:`rotomorph.solve.banded`) and network
Hessians a compiled sparse Cholesky with a cached symbolic analysis
(:mod:`rotomorph.solve.sparse_cholesky`); both fail on a non-positive pivot. Other SciPy sparse
matrices use SuperLU in symmetric mode with a symmetric fill-reducing ordering and no pivoting
(``diag_pivot_thresh = 0``): then ``P A P^T = L U`` with ``U = D L^T``, so by Sylvester's law
of inertia ``A`` is positive definite exactly when every diagonal entry of ``U`` is positive.
Dense matrices use LAPACK ``potrf``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit
from scipy.linalg import lapack

from rotomorph._typing import FloatArray, IntArray
from rotomorph.solve.banded import banded_cholesky, banded_cholesky_solve
from rotomorph.solve.sparse_cholesky import Symbolic, factor


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


class SparseMatrix:
    """A symmetric sparse matrix (full pattern, CSC) with its cached symbolic Cholesky.

    Made from a SciPy CSC matrix, or (:meth:`from_arrays`, as the Newton loop refills a fixed
    pattern) from its CSC arrays alone: the SciPy matrix is then built only when ``csc`` is
    asked for, since its constructor's checks cost more than refilling the values. Diagonal
    and products come from the arrays (the same sums in the same order as SciPy's).
    """

    __slots__ = ("_csc", "data", "indices", "indptr", "symbolic")

    def __init__(self, csc: sp.csc_matrix, symbolic: Symbolic) -> None:
        self._csc: sp.csc_matrix | None = csc
        self.data: FloatArray = csc.data
        self.indices: IntArray = csc.indices
        self.indptr: IntArray = csc.indptr
        self.symbolic = symbolic

    @classmethod
    def from_arrays(
        cls, data: FloatArray, indices: IntArray, indptr: IntArray, symbolic: Symbolic
    ) -> SparseMatrix:
        """The matrix with CSC arrays ``data, indices, indptr`` (full symmetric pattern, rows
        sorted in each column, the pattern ``symbolic`` was analysed for)."""
        out = cls.__new__(cls)
        out._csc = None
        out.data, out.indices, out.indptr, out.symbolic = data, indices, indptr, symbolic
        return out

    @property
    def n(self) -> int:
        """Matrix size."""
        return len(self.indptr) - 1

    @property
    def csc(self) -> sp.csc_matrix:
        """The SciPy CSC matrix (built at the first request)."""
        if self._csc is None:
            n = self.n
            self._csc = sp.csc_matrix((self.data, self.indices, self.indptr), shape=(n, n))
        return self._csc

    def diagonal(self) -> FloatArray:
        """Main diagonal."""
        sym = self.symbolic
        if sym.n != self.n:  # pragma: no cover - a symbolic analysis of another pattern
            return np.asarray(self.csc.diagonal())
        out = np.zeros(sym.n)
        have = sym.diag_src >= 0
        out[sym.perm[have]] = self.data[sym.diag_src[have]]
        return out

    def toarray(self) -> FloatArray:
        """Dense copy (for tests)."""
        return np.asarray(self.csc.toarray())

    to_dense = toarray


@njit(cache=True)
def _csc_matvec(indptr, indices, data, x):  # pragma: no cover - compiled
    """``A @ x`` in SciPy's order (``csc_matvec``: column by column)."""
    y = np.zeros(indptr.shape[0] - 1)
    for j in range(indptr.shape[0] - 1):
        xj = x[j]
        for p in range(indptr[j], indptr[j + 1]):
            y[indices[p]] += data[p] * xj
    return y


@njit(cache=True)
def _banded_matvec(ab, u, x):  # pragma: no cover - compiled
    n = ab.shape[1]
    y = np.zeros(n)
    for j in range(n):
        y[j] += ab[u, j] * x[j]
        for i in range(max(0, j - u), j):
            a = ab[u + i - j, j]
            y[i] += a * x[j]
            y[j] += a * x[i]
    return y


@njit(cache=True)
def _csc_matmat(indptr, indices, data, X):  # pragma: no cover - compiled
    """``A @ X`` column by column, each in the order of :func:`_csc_matvec`."""
    Y = np.zeros((indptr.shape[0] - 1, X.shape[1]))
    for c in range(X.shape[1]):
        for j in range(indptr.shape[0] - 1):
            xj = X[j, c]
            for p in range(indptr[j], indptr[j + 1]):
                Y[indices[p], c] += data[p] * xj
    return Y


def matmat(H: Any, X: FloatArray) -> FloatArray:
    """``H @ X`` ``(n, k)`` for a banded, sparse or dense symmetric matrix; each column as
    :func:`matvec` computes it."""
    if isinstance(H, SparseMatrix):
        return _csc_matmat(H.indptr, H.indices, H.data, np.asarray(X, dtype=float))
    cols = [matvec(H, np.ascontiguousarray(X[:, j])) for j in range(X.shape[1])]
    return np.column_stack(cols) if cols else np.zeros((len(X), 0))


def diagonal(H: Any) -> FloatArray:
    """Main diagonal of a banded, sparse or dense symmetric matrix."""
    if isinstance(H, BandedMatrix):
        return H.diagonal
    return np.asarray(H.diagonal())


def matvec(H: Any, x: FloatArray) -> FloatArray:
    """``H @ x`` for a banded, sparse or dense symmetric matrix."""
    if isinstance(H, BandedMatrix):
        return _banded_matvec(H.ab, H.u, x)
    if isinstance(H, SparseMatrix):
        return _csc_matvec(H.indptr, H.indices, H.data, np.ascontiguousarray(x, dtype=float))
    return np.asarray(H @ x)


class Factor:
    """A Cholesky-type factorization of a positive definite matrix; ``solve(rhs)``."""

    def __init__(self, kind: str, data: Any) -> None:
        self._kind, self._data = kind, data

    @property
    def kind(self) -> str:
        """``"banded"``, ``"cholesky"`` (compiled sparse), ``"sparse"`` (SuperLU) or ``"dense"``."""
        return self._kind

    @property
    def data(self) -> Any:
        """The factor itself: ``(U, u)`` banded, a :class:`SparseCholesky`, SuperLU's object or
        LAPACK's upper triangle."""
        return self._data

    def solve(self, rhs: FloatArray) -> FloatArray:
        """Solve with the factored matrix."""
        if self._kind == "banded":
            c, u = self._data
            return banded_cholesky_solve(c, u, rhs)
        if self._kind in ("sparse", "cholesky"):
            return self._data.solve(rhs)
        x, _ = lapack.dpotrs(self._data, rhs, lower=0)
        return x


def factorize(H: Any, shift: FloatArray) -> Factor | None:
    """Factor ``H + diag(shift)``; ``None`` when it is not positive definite."""
    if isinstance(H, BandedMatrix):
        work = H.ab.copy(order="F")
        work[H.u] += shift
        if not banded_cholesky(work, H.u):
            return None
        return Factor("banded", (work, H.u))
    if isinstance(H, SparseMatrix):
        chol = factor(H.symbolic, H.data, shift)
        return None if chol is None else Factor("cholesky", chol)
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
        dg = lu.U.diagonal()
        # a row interchange would invalidate the inertia argument
        if not (
            np.all(np.isfinite(dg)) and np.all(dg > 0) and np.array_equal(lu.perm_r, lu.perm_c)
        ):
            return None
        return Factor("sparse", lu)
    c, info = lapack.dpotrf(np.asarray(H) + np.diag(shift), lower=0)
    if info != 0:
        return None
    return Factor("dense", c)


def solve_shifted(H: Any, rhs: FloatArray, shift: FloatArray) -> FloatArray | None:
    """Solve ``(H + diag(shift)) x = rhs`` if the shifted matrix is positive definite."""
    f = factorize(H, shift)
    return None if f is None else f.solve(rhs)
