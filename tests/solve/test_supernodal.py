"""The supernodal sparse Cholesky against dense LAPACK on the pattern of a lattice's Hessian
(with contact-like couplings added), and the definiteness it reports."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.rod.stencils import build_stencils, dof_layout
from rotomorph.solve.linalg import SparseMatrix, factorize
from rotomorph.solve.pattern import hessian_pattern
from rotomorph.solve.sparse_cholesky import analyse, factor


def _lattice_pattern(n: int, contacts: int, rng: np.random.Generator) -> sp.csc_matrix:
    """The reduced Hessian pattern of an ``n x n`` sinusoidal lattice (first node fixed) plus
    ``contacts`` random 3 x 3 node-to-node coupling blocks (as contact adds)."""
    net = sinusoidal_lattice(n).network
    st, lay = build_stencils(net), dof_layout(net)
    reduced = np.arange(lay.count, dtype=np.int64)
    reduced[:3] = -1
    reduced[3:] = np.arange(lay.count - 3)
    indices, indptr = hessian_pattern(lay.stencil_dofs(st), lay.edge_dofs(net.edges), reduced)[2]
    m = lay.count - 3
    pattern = sp.csc_matrix((np.ones(len(indices)), indices, indptr), shape=(m, m))
    nodes = rng.choice(np.arange(1, net.n_nodes), size=(contacts, 2), replace=False)
    rows, cols = [np.zeros(0, dtype=np.int64)], [np.zeros(0, dtype=np.int64)]
    for a, b in nodes:
        ia, ib = reduced[lay.pos[a] + np.arange(3)], reduced[lay.pos[b] + np.arange(3)]
        for u, v in ((ia, ib), (ib, ia)):
            rows.append(np.repeat(u, 3))
            cols.append(np.tile(v, 3))
    extra = sp.csc_matrix(
        (np.ones(9 * 2 * contacts), (np.concatenate(rows), np.concatenate(cols))), shape=(m, m)
    )
    out = (pattern + extra).tocsc()
    out.sort_indices()
    return out


def _random_spd_on(pattern: sp.csc_matrix, rng: np.random.Generator) -> sp.csc_matrix:
    """Random symmetric values on ``pattern``, made diagonally dominant (positive definite)."""
    a = sp.triu(pattern, k=1).tocoo()
    off = sp.csc_matrix((rng.normal(size=a.nnz), (a.row, a.col)), shape=pattern.shape)
    off = off + off.T
    diag = np.asarray(abs(off).sum(axis=1)).ravel() + rng.uniform(0.1, 1.0, pattern.shape[0])
    out = (off + sp.diags(diag)).tocsc()
    out.sort_indices()
    return out


@pytest.mark.parametrize(("n", "contacts"), [(2, 0), (3, 6), (4, 20)])
def test_supernodal_factor_equals_dense_cholesky(n, contacts, rng):
    A = _random_spd_on(_lattice_pattern(n, contacts, rng), rng)
    sym = analyse(A)
    assert A.shape[0] > 100 and len(sym.supernodal[0]) - 1 < A.shape[0]  # some real supernodes
    shift = rng.uniform(0.0, 0.5, A.shape[0])
    chol = factor(sym, A.data, shift)
    assert chol is not None
    B = (A + sp.diags(shift)).toarray()[np.ix_(sym.perm, sym.perm)]
    want = np.linalg.cholesky(B)
    np.testing.assert_allclose(chol.lower(), want, rtol=0, atol=1e-12 * np.abs(want).max())
    # its fill is the analysed pattern's: no entry of L outside it
    assert np.count_nonzero(np.abs(want) > 1e-14) <= sym.lp[-1]
    b = rng.normal(size=A.shape[0])
    x = chol.solve(b)
    np.testing.assert_allclose((A + sp.diags(shift)) @ x, b, atol=1e-10 * np.abs(b).max())


def test_supernodal_factor_reports_the_first_non_positive_pivot(rng):
    A = _random_spd_on(_lattice_pattern(3, 6, rng), rng)
    H = SparseMatrix(A, analyse(A))
    lam = np.linalg.eigvalsh(A.toarray())
    # indefinite by a margin: any pivot order must meet a non-positive pivot
    assert factorize(H, np.full(A.shape[0], -0.5 * (lam[0] + lam[1]))) is None
    assert factorize(H, np.full(A.shape[0], 1e-3 - lam[0])) is not None
    # one negative diagonal entry of a diagonal-dominant matrix, wherever it sits in the order
    sym = H.symbolic
    for where in (0, A.shape[0] // 2, A.shape[0] - 1):
        shift = np.zeros(A.shape[0])
        j = int(sym.perm[where])
        shift[j] = -A[j, j] - 1.0
        assert factor(sym, A.data, shift) is None


def test_analysis_lists_the_permuted_upper_triangle_by_column_then_row(rng):
    A = _random_spd_on(_lattice_pattern(3, 6, rng), rng)
    perm = rng.permutation(A.shape[0]).astype(np.int64)
    sym = analyse(A, perm)
    inv = np.argsort(perm)
    col = np.repeat(np.arange(A.shape[0]), np.diff(A.indptr))
    bi, bj = inv[A.indices], inv[col]
    upper = np.flatnonzero(bi <= bj)
    order = upper[np.lexsort((bi[upper], bj[upper]))]
    np.testing.assert_array_equal(sym.src, order)
    np.testing.assert_array_equal(sym.bi, bi[order])
    np.testing.assert_array_equal(np.diff(sym.bp), np.bincount(bj[order], minlength=A.shape[0]))
    np.testing.assert_array_equal(A.data[sym.src[sym.bp[1:] - 1]], A.diagonal()[perm])


@pytest.mark.parametrize(("n", "contacts"), [(2, 0), (3, 6), (5, 40), (5, 150)])
def test_the_ordering_is_the_one_a_complete_factorization_finds(n, contacts, rng):
    """The minimum-degree ordering taken from an incomplete factorization that drops every
    off-diagonal entry is SuperLU's ordering from a complete factorization of the stand-in."""
    import scipy.sparse.linalg as spla

    from rotomorph.solve.sparse_cholesky import ordering

    A = _lattice_pattern(n, contacts, rng)
    pattern = sp.csc_matrix((np.ones(A.nnz), A.indices, A.indptr), shape=A.shape)
    degree = np.asarray(abs(pattern).sum(axis=0)).ravel()
    lu = spla.splu(
        (pattern + sp.diags(degree + 1.0)).tocsc(), permc_spec="MMD_AT_PLUS_A",
        diag_pivot_thresh=0.0, options={"SymmetricMode": True},
    )  # fmt: skip
    perm = ordering(A)
    assert np.array_equal(perm, np.argsort(lu.perm_c))
    assert not np.array_equal(perm, np.arange(A.shape[0]))  # a real reordering
