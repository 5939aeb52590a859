"""Factorizations: compiled banded and sparse Cholesky against dense references, and the
definiteness they report (what modified Newton relies on)."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp

from rotomorph.solve.banded import banded_cholesky, banded_cholesky_solve
from rotomorph.solve.linalg import BandedMatrix, SparseMatrix, factorize, matvec
from rotomorph.solve.sparse_cholesky import analyse


def _random_sparse_spd(rng, n=300, density=0.02):
    a = sp.random(n, n, density=density, random_state=np.random.RandomState(1), format="csc")
    a = a + a.T
    return (a + sp.diags(np.asarray(abs(a).sum(axis=1)).ravel() + 1.0)).tocsc()


def test_sparse_cholesky_solves_like_a_dense_solver(rng):
    A = _random_sparse_spd(rng)
    A.sort_indices()
    H = SparseMatrix(A, analyse(A))
    b = rng.normal(size=A.shape[0])
    fac = factorize(H, np.zeros(A.shape[0]))
    np.testing.assert_allclose(fac.solve(b), np.linalg.solve(A.toarray(), b), rtol=1e-10)
    np.testing.assert_allclose(matvec(H, b), A @ b)


def test_sparse_cholesky_reports_indefiniteness_and_shifts(rng):
    A = _random_sparse_spd(rng)
    A.sort_indices()
    lam_min = np.linalg.eigvalsh(A.toarray()).min()
    B = (A - sp.diags(np.full(A.shape[0], lam_min + 0.5))).tocsc()
    B.sort_indices()
    H = SparseMatrix(B, analyse(B))
    assert factorize(H, np.zeros(B.shape[0])) is None
    assert factorize(H, np.full(B.shape[0], 0.6)) is not None


@pytest.mark.parametrize("u", [1, 4, 10])
def test_banded_cholesky_matches_dense(rng, u):
    n = 60
    A = np.zeros((n, n))
    for i in range(n):
        for j in range(max(0, i - u), i):
            A[i, j] = A[j, i] = rng.normal()
    A += np.diag(np.abs(A).sum(axis=1) + 1.0)
    ab = np.zeros((u + 1, n), order="F")
    for j in range(n):
        for i in range(max(0, j - u), j + 1):
            ab[u + i - j, j] = A[i, j]
    np.testing.assert_allclose(BandedMatrix(ab, u).to_dense(), A)
    c = ab.copy(order="F")
    assert banded_cholesky(c, u)
    b = rng.normal(size=n)
    np.testing.assert_allclose(banded_cholesky_solve(c, u, b), np.linalg.solve(A, b), rtol=1e-10)
    bad = ab.copy(order="F")
    bad[u, n // 2] = -1.0
    assert not banded_cholesky(bad, u)
