"""Compiled sparse Cholesky factorization with a symbolic analysis reused across Newton steps.

Networks (lattices) give Hessians that are sparse but not banded. Their sparsity pattern is
fixed by the topology, so the fill-reducing ordering, the elimination tree and the pattern of
the factor are computed once (:func:`analyse`) and every later factorization is purely numeric
(:func:`factor`). The numeric phase is the up-looking algorithm of CSparse (Davis, *Direct
Methods for Sparse Linear Systems*, SIAM 2006, §4.7: ``cs_etree``, ``cs_ereach``, ``cs_chol``);
a non-positive pivot reports that the (shifted) matrix is not positive definite, which is what
modified Newton needs. The ordering is the minimum-degree ordering SuperLU computes for
``A + A^T`` (SciPy's ``splu`` with ``MMD_AT_PLUS_A``), taken once from a factorization of the
pattern.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from rotomorph._typing import FloatArray, IntArray


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
    def row_pattern(self) -> tuple[IntArray, IntArray, IntArray, IntArray]:
        """``li, rp, rows, slot``: the row indices of L (fixed by the pattern, shared by every
        numeric factor) and row k of L off the diagonal, ``rows[rp[k]:rp[k + 1]]``, in the
        topological order of the elimination tree with the position (``slot``) of each entry
        in L's arrays; found at the first factorization (a pattern analysed only to measure
        its fill is never factored)."""
        return _row_patterns(self.n, self.bp, self.bi, self.parent, self.lp)  # type: ignore[no-any-return]


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
def _ereach(k, bp, bi, parent, s, w):  # pragma: no cover - compiled
    """Pattern of row k of L (columns < k) in s[top:], topologically ordered."""
    n = s.shape[0]
    top = n
    w[k] = k
    for p in range(bp[k], bp[k + 1]):
        i = bi[p]
        if i > k:
            continue
        length = 0
        while w[i] != k:
            s[length] = i
            length += 1
            w[i] = k
            i = parent[i]
        while length > 0:
            top -= 1
            length -= 1
            s[top] = s[length]
    return top


@njit(cache=True)
def _column_counts(n, bp, bi, parent):  # pragma: no cover - compiled
    counts = np.ones(n, dtype=np.int64)
    s = np.empty(n, dtype=np.int64)
    w = -np.ones(n, dtype=np.int64)
    for k in range(n):
        top = _ereach(k, bp, bi, parent, s, w)
        for t in range(top, n):
            counts[s[t]] += 1
    return counts


@njit(cache=True)
def _row_patterns(n, bp, bi, parent, lp):  # pragma: no cover - compiled
    """Row indices ``li`` of L and the pattern of every row of L in the order the up-looking
    factorization visits it (``cs_ereach``): ``rows[rp[k]:rp[k + 1]]`` with the ``slot`` of
    each entry in L's arrays. Both depend on the pattern only, so every numeric factorization
    of it reuses them instead of walking the elimination tree again."""
    nnz = lp[n]
    li = np.empty(nnz, dtype=np.int64)
    rp = np.empty(n + 1, dtype=np.int64)
    rows = np.empty(nnz - n, dtype=np.int64)
    slot = np.empty(nnz - n, dtype=np.int64)
    c = lp[:-1].copy()
    s = np.empty(n, dtype=np.int64)
    w = -np.ones(n, dtype=np.int64)
    m = 0
    for k in range(n):
        rp[k] = m
        top = _ereach(k, bp, bi, parent, s, w)
        for t in range(top, n):
            i = s[t]
            rows[m] = i
            slot[m] = c[i]
            li[c[i]] = k
            c[i] += 1
            m += 1
        li[c[k]] = k
        c[k] += 1
    rp[n] = m
    return li, rp, rows, slot


@njit(cache=True)
def _numeric(n, bp, bi, bx, shift, lp, li, rp, rows, slot, lx):  # pragma: no cover - compiled
    """Up-looking Cholesky of B + diag(shift) into ``lx``; False at a non-positive pivot.

    Row k: ``L[k, :k]`` solves ``L[:k, :k] y = B[:k, k]`` over the row's pattern (in
    elimination-tree order), then ``L[k, k] = sqrt(B[k, k] - y.y)``. The operations and their
    order are those of CSparse's ``cs_chol``, with the pattern precomputed.
    """
    x = np.zeros(n)
    for k in range(n):
        for p in range(bp[k], bp[k + 1]):
            i = bi[p]
            if i <= k:
                x[i] = bx[p]
        d = x[k] + shift[k]
        x[k] = 0.0
        for t in range(rp[k], rp[k + 1]):
            i = rows[t]
            lki = x[i] / lx[lp[i]]
            x[i] = 0.0
            end = slot[t]
            for p in range(lp[i] + 1, end):
                x[li[p]] -= lx[p] * lki
            d -= lki * lki
            lx[end] = lki
        if not d > 0.0:
            return False
        lx[lp[k]] = np.sqrt(d)
    return True


@njit(cache=True)
def _solve(n, lp, li, lx, perm, b):  # pragma: no cover - compiled
    y = np.empty(n)
    for i in range(n):
        y[i] = b[perm[i]]
    for j in range(n):
        y[j] /= lx[lp[j]]
        for p in range(lp[j] + 1, lp[j + 1]):
            y[li[p]] -= lx[p] * y[j]
    for j in range(n - 1, -1, -1):
        v = y[j]
        for p in range(lp[j] + 1, lp[j + 1]):
            v -= lx[p] * y[li[p]]
        y[j] = v / lx[lp[j]]
    out = np.empty(n)
    for i in range(n):
        out[perm[i]] = y[i]
    return out


def analyse(A: sp.csc_matrix, perm: IntArray | None = None) -> Symbolic:
    """Ordering, elimination tree and factor pattern of the symmetric pattern of ``A``.

    ``perm``: a fill-reducing ordering to keep (e.g. that of a pattern ``A`` has grown from);
    default: a new minimum-degree ordering.
    """
    A = sp.csc_matrix(A)
    A.sort_indices()
    n = A.shape[0]
    if perm is None:
        perm = ordering(A)
    inv = np.empty(n, dtype=np.int64)
    inv[perm] = np.arange(n)
    # upper triangle of B = A[perm][:, perm], with a map back into A.data
    coo_row = A.indices.astype(np.int64)
    coo_col = np.repeat(np.arange(n), np.diff(A.indptr))
    bi_all, bj_all = inv[coo_row], inv[coo_col]
    upper = bi_all <= bj_all
    # by column, then row: one sort of the combined key (np.lexsort's order; a canonical matrix
    # has no repeated entry, so the keys are distinct and any sort gives that order)
    key = bj_all[upper] * n + bi_all[upper]
    order = np.argsort(key) if A.has_canonical_format else np.argsort(key, kind="stable")
    src = np.flatnonzero(upper)[order].astype(np.int64)
    bi = bi_all[upper][order].astype(np.int64)
    bj = bj_all[upper][order]
    bp = np.concatenate([[0], np.cumsum(np.bincount(bj, minlength=n))]).astype(np.int64)
    diag_src = np.full(n, -1, dtype=np.int64)
    is_diag = bi == bj
    diag_src[bj[is_diag]] = src[is_diag]
    parent = _etree(n, bp, bi)
    counts = _column_counts(n, bp, bi, parent)
    lp = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return Symbolic(n=n, perm=perm, bp=bp, bi=bi, src=src, diag_src=diag_src, parent=parent, lp=lp)


def ordering(A: sp.csc_matrix) -> IntArray:
    """Minimum-degree ordering of the symmetric pattern of ``A`` (SuperLU's, on ``A + A^T``)."""
    # a positive definite stand-in with A's pattern, to obtain SuperLU's ordering
    pattern = sp.csc_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    degree = np.asarray(abs(pattern).sum(axis=0)).ravel()
    stand_in = (pattern + sp.diags(degree + 1.0)).tocsc()
    lu = spla.splu(
        stand_in, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
    )
    return np.argsort(lu.perm_c).astype(np.int64)


class SparseCholesky:
    """Numeric factor of ``A + diag(shift)`` with a cached :class:`Symbolic`; ``solve(b)``."""

    def __init__(self, sym: Symbolic, lx: FloatArray) -> None:
        self._sym, self._lx = sym, lx

    def solve(self, b: FloatArray) -> FloatArray:
        """Solve with the factored matrix."""
        s = self._sym
        return _solve(s.n, s.lp, s.row_pattern[0], self._lx, s.perm, np.ascontiguousarray(b, float))


def factor(sym: Symbolic, data: FloatArray, shift: FloatArray) -> SparseCholesky | None:
    """Factor the matrix with CSC ``data`` (pattern of ``sym``) plus ``diag(shift)``.

    Returns ``None`` when it is not positive definite.
    """
    lx = np.empty(int(sym.lp[-1]))
    bx = np.ascontiguousarray(data[sym.src])
    sh = np.ascontiguousarray(np.broadcast_to(shift, (sym.n,)), dtype=float)[sym.perm]
    ok = _numeric(sym.n, sym.bp, sym.bi, bx, sh, sym.lp, *sym.row_pattern, lx)
    return SparseCholesky(sym, lx) if ok else None
