"""Compiled sparse Cholesky factorization with a symbolic analysis reused across Newton steps.

Networks (lattices) give Hessians that are sparse but not banded. Their sparsity pattern is
fixed by the topology, so the fill-reducing ordering, the elimination tree and the pattern of
the factor are computed once (:func:`analyse`: ``cs_etree`` and the row patterns of
``cs_ereach`` in Davis, *Direct Methods for Sparse Linear Systems*, SIAM 2006, §4) and every
later factorization is purely numeric (:func:`factor`): a supernodal left-looking Cholesky on
dense panels (:mod:`rotomorph.solve.supernodal`). A non-positive pivot reports that the
(shifted) matrix is not positive definite, which is what modified Newton needs. The ordering is
the minimum-degree ordering SuperLU computes for ``A + A^T`` (``MMD_AT_PLUS_A``), taken from
an incomplete factorization (SciPy's ``spilu``) of a stand-in with the pattern that drops every
off-diagonal entry: SuperLU orders the columns from the pattern alone before it factors, so
this is the ordering a complete factorization (``splu``) finds, for a fraction of its cost.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from rotomorph._typing import FloatArray, IntArray
from rotomorph.solve.supernodal import ereach, factor_numeric, solve_numeric, supernodes

#: drop tolerance of the incomplete factorization that :func:`ordering` runs for its ordering
#: only: every off-diagonal entry of the (diagonally dominant) stand-in falls below it
_DROP_ALL = 1e300


@dataclass(frozen=True, eq=False)
class Symbolic:
    """Ordering and factor pattern of a symmetric sparse matrix (CSC, full pattern)."""

    n: int
    perm: IntArray  # B = A[perm][:, perm]
    bp: IntArray  # upper triangle of B, CSC column pointers
    bi: IntArray  # its row indices
    src: IntArray  # position of each upper-B entry in the data array of A
    diag_src: IntArray  # position of B's diagonal entries in the data array of A (per column)
    parent: IntArray  # elimination tree
    lp: IntArray  # column pointers of L

    @cached_property
    def supernodal(
        self,
    ) -> tuple[IntArray, IntArray, IntArray, IntArray, IntArray, IntArray, IntArray]:
        """The supernodal structure of the factor (:func:`rotomorph.solve.supernodal.supernodes`:
        ``first, rp, ri, px, snode, dst, diag``), found at the first factorization (a pattern
        analysed only to measure its fill is never factored)."""
        return supernodes(self.n, self.bp, self.bi, self.parent, self.lp)  # type: ignore[no-any-return]


@njit(cache=True)
def _etree(n, bp, bi):  # pragma: no cover - compiled
    parent = -np.ones(n, dtype=np.int64)
    ancestor = -np.ones(n, dtype=np.int64)
    for k in range(n):
        for p in range(bp[k], bp[k + 1]):
            i = bi[p]
            while i != -1 and i < k:
                nxt = ancestor[i]
                ancestor[i] = k
                if nxt == -1:
                    parent[i] = k
                i = nxt
    return parent


@njit(cache=True)
def _column_counts(n, bp, bi, parent):  # pragma: no cover - compiled
    counts = np.ones(n, dtype=np.int64)
    s = np.empty(n, dtype=np.int64)
    w = -np.ones(n, dtype=np.int64)
    for k in range(n):
        top = ereach(k, bp, bi, parent, s, w)
        for t in range(top, n):
            counts[s[t]] += 1
    return counts


@njit(cache=True)
def _stable_by(key, n, order):  # pragma: no cover - compiled
    """``order`` rearranged so that ``key[order]`` ascends (``0 <= key < n``), ties kept in
    their order (one counting-sort pass)."""
    start = np.zeros(n + 1, dtype=np.int64)
    for q in order:
        start[key[q] + 1] += 1
    for i in range(n):
        start[i + 1] += start[i]
    out = np.empty_like(order)
    for q in order:
        out[start[key[q]]] = q
        start[key[q]] += 1
    return out


@njit(cache=True)
def _permuted_upper(n, indptr, indices, inv):  # pragma: no cover - compiled
    """Upper triangle of ``B = A[perm][:, perm]`` in CSC (rows ascending; repeated entries in
    their order in ``A``) and the position ``src`` of each entry in ``A``'s data: a stable
    counting sort by row, then by column."""
    rows = np.empty(indptr[n], dtype=np.int64)
    cols = np.empty(indptr[n], dtype=np.int64)
    src = np.empty(indptr[n], dtype=np.int64)
    m = 0
    for col in range(n):
        for p in range(indptr[col], indptr[col + 1]):
            if inv[indices[p]] <= inv[col]:
                rows[m], cols[m], src[m] = inv[indices[p]], inv[col], p
                m += 1
    order = _stable_by(cols, n, _stable_by(rows, n, np.arange(m)))
    bp = np.zeros(n + 1, dtype=np.int64)
    for q in range(m):
        bp[cols[q] + 1] += 1
    for j in range(n):
        bp[j + 1] += bp[j]
    return bp, rows[order], src[order]


def analyse(A: sp.csc_matrix, perm: IntArray | None = None) -> Symbolic:
    """Ordering, elimination tree and factor pattern of the symmetric pattern of ``A``.

    ``perm``: a fill-reducing ordering to keep (e.g. that of a pattern ``A`` has grown from);
    default: a new minimum-degree ordering.
    """
    A = sp.csc_matrix(A)
    A.sort_indices()
    return analyse_pattern(A.indptr, A.indices, perm)


def analyse_pattern(indptr: IntArray, indices: IntArray, perm: IntArray | None = None) -> Symbolic:
    """:func:`analyse` of the pattern given by its CSC arrays (row indices ascending in each
    column), without building a matrix unless a new ordering is needed."""
    n = len(indptr) - 1
    if perm is None:
        perm = ordering(sp.csc_matrix((np.ones(len(indices)), indices, indptr), shape=(n, n)))
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    bp, bi, src = _permuted_upper(
        n, np.asarray(indptr, dtype=np.int64), np.asarray(indices, dtype=np.int64), inv
    )
    bj = np.repeat(np.arange(n), np.diff(bp))
    diag_src = np.full(n, -1, dtype=np.int64)
    is_diag = bi == bj
    diag_src[bj[is_diag]] = src[is_diag]
    parent = _etree(n, bp, bi)
    counts = _column_counts(n, bp, bi, parent)
    lp = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return Symbolic(n=n, perm=perm, bp=bp, bi=bi, src=src, diag_src=diag_src, parent=parent, lp=lp)


def ordering(A: sp.csc_matrix) -> IntArray:
    """Minimum-degree ordering of the symmetric pattern of ``A`` (SuperLU's, on ``A + A^T``)."""
    # a positive definite stand-in with A's pattern, to obtain SuperLU's ordering. SuperLU
    # finds the column ordering (the minimum-degree ordering of A + A^T, postordered along
    # its elimination tree) from the pattern alone, before and whatever the numeric
    # factorization, and its incomplete factorization finds it the same way: one that drops
    # every off-diagonal entry returns the same ordering at a fraction of a complete one's cost
    pattern = sp.csc_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    degree = np.asarray(abs(pattern).sum(axis=0)).ravel()
    stand_in = (pattern + sp.diags(degree + 1.0)).tocsc()
    lu = spla.spilu(
        stand_in, drop_tol=_DROP_ALL, fill_factor=1.0, permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0, options={"SymmetricMode": True},
    )  # fmt: skip
    return np.argsort(lu.perm_c).astype(np.int64)


class SparseCholesky:
    """Numeric factor of ``A + diag(shift)`` with a cached :class:`Symbolic`; ``solve(b)``."""

    def __init__(self, sym: Symbolic, lx: FloatArray) -> None:
        self._sym, self._lx = sym, lx

    @property
    def arrays(self) -> tuple[tuple[IntArray, IntArray, IntArray, IntArray], FloatArray, IntArray]:
        """``(first, rp, ri, px)``, the values ``lx`` and the ordering ``perm`` that
        :func:`rotomorph.solve.supernodal.solve_numeric` takes."""
        first, rp, ri, px = self._sym.supernodal[:4]
        return (first, rp, ri, px), self._lx, self._sym.perm

    def solve(self, b: FloatArray) -> FloatArray:
        """Solve with the factored matrix."""
        first, rp, ri, px = self._sym.supernodal[:4]
        b = np.ascontiguousarray(b, dtype=float)
        return solve_numeric(first, rp, ri, px, self._lx, self._sym.perm, b)  # type: ignore[no-any-return]

    def lower(self) -> FloatArray:
        """The factor ``L`` of the permuted matrix ``A[perm][:, perm]`` as a dense array (for
        tests)."""
        first, rp, ri, px = self._sym.supernodal[:4]
        out = np.zeros((self._sym.n, self._sym.n))
        for s in range(len(first) - 1):
            rows = ri[rp[s] : rp[s + 1]]
            width = int(first[s + 1] - first[s])
            panel = self._lx[px[s] : px[s + 1]].reshape(width, len(rows)).T
            out[rows, first[s] : first[s + 1]] = panel
        return np.tril(out)


def factor(sym: Symbolic, data: FloatArray, shift: FloatArray) -> SparseCholesky | None:
    """Factor the matrix with CSC ``data`` (pattern of ``sym``) plus ``diag(shift)``.

    Returns ``None`` when it is not positive definite.
    """
    structure = sym.supernodal
    lx = np.empty(int(structure[3][-1]))
    sh = np.ascontiguousarray(np.broadcast_to(shift, (sym.n,)), dtype=float)[sym.perm]
    ok = factor_numeric(np.ascontiguousarray(data, dtype=float), sym.src, sh, *structure, lx)
    return SparseCholesky(sym, lx) if ok else None
