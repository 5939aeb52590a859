r"""Projection of a small symmetric matrix onto the positive semidefinite cone (compiled).

The projection :math:`P = \sum_{\lambda_k > 0} \lambda_k v_k v_k^T` keeps the positive part of
the eigen-decomposition :math:`H = \sum_k \lambda_k v_k v_k^T`; it is the nearest positive
semidefinite matrix in the Frobenius norm. The contact barrier projects one 12 x 12 block per
active pair and Newton iteration, where LAPACK's ``dsyevd`` costs more in call overhead than in
arithmetic, so the eigen-decomposition is done here in place, without allocation: Householder
reduction to tridiagonal form and the implicit QL iteration with Wilkinson-type shifts
(``tred2`` / ``tql2`` of Martin, Reinsch & Wilkinson, *Numer. Math.* 11 (1968) 181 and
Bowdler et al., *Numer. Math.* 11 (1968) 293, as in the public-domain JAMA library). Both are
backward stable: the result agrees with any other stable eigensolver's to round-off.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

#: QL sweeps allowed per eigenvalue before falling back to LAPACK (a few suffice)
MAX_SWEEPS = 60


@njit(cache=True)
def _tridiagonalize(V, d, e):  # pragma: no cover - compiled
    """Householder reduction of the symmetric ``V`` (n, n) to tridiagonal form: diagonal
    ``d``, sub-diagonal ``e[1:]``; ``V`` becomes the accumulated orthogonal transformation."""
    n = d.shape[0]
    for j in range(n):
        d[j] = V[n - 1, j]
    for i in range(n - 1, 0, -1):
        scale = 0.0
        h = 0.0
        for k in range(i):
            scale += abs(d[k])
        if scale == 0.0:
            e[i] = d[i - 1]
            for j in range(i):
                d[j] = V[i - 1, j]
                V[i, j] = 0.0
                V[j, i] = 0.0
        else:
            for k in range(i):
                d[k] /= scale
                h += d[k] * d[k]
            f = d[i - 1]
            g = math.sqrt(h)
            if f > 0.0:
                g = -g
            e[i] = scale * g
            h = h - f * g
            d[i - 1] = f - g
            for j in range(i):
                e[j] = 0.0
            for j in range(i):
                f = d[j]
                V[j, i] = f
                g = e[j] + V[j, j] * f
                for k in range(j + 1, i):
                    g += V[k, j] * d[k]
                    e[k] += V[k, j] * f
                e[j] = g
            f = 0.0
            for j in range(i):
                e[j] /= h
                f += e[j] * d[j]
            hh = f / (h + h)
            for j in range(i):
                e[j] -= hh * d[j]
            for j in range(i):
                f = d[j]
                g = e[j]
                for k in range(j, i):
                    V[k, j] -= f * e[k] + g * d[k]
                d[j] = V[i - 1, j]
                V[i, j] = 0.0
        d[i] = h
    # accumulate the transformations
    for i in range(n - 1):
        V[n - 1, i] = V[i, i]
        V[i, i] = 1.0
        h = d[i + 1]
        if h != 0.0:
            for k in range(i + 1):
                d[k] = V[k, i + 1] / h
            for j in range(i + 1):
                g = 0.0
                for k in range(i + 1):
                    g += V[k, i + 1] * V[k, j]
                for k in range(i + 1):
                    V[k, j] -= g * d[k]
        for k in range(i + 1):
            V[k, i + 1] = 0.0
    for j in range(n):
        d[j] = V[n - 1, j]
        V[n - 1, j] = 0.0
    V[n - 1, n - 1] = 1.0
    e[0] = 0.0


@njit(cache=True)
def _ql_implicit(V, d, e):  # pragma: no cover - compiled
    """Eigenvalues ``d`` and eigenvectors (columns of ``V``) of the tridiagonal matrix from
    :func:`_tridiagonalize`; False when an eigenvalue does not converge."""
    n = d.shape[0]
    for i in range(1, n):
        e[i - 1] = e[i]
    e[n - 1] = 0.0
    f = 0.0
    tst1 = 0.0
    eps = 2.0**-52
    for lo in range(n):
        tst1 = max(tst1, abs(d[lo]) + abs(e[lo]))
        m = lo
        while m < n - 1 and abs(e[m]) > eps * tst1:
            m += 1
        if m > lo:
            sweeps = 0
            while True:
                sweeps += 1
                if sweeps > MAX_SWEEPS:
                    return False
                g = d[lo]
                p = (d[lo + 1] - g) / (2.0 * e[lo])
                r = math.hypot(p, 1.0)
                if p < 0.0:
                    r = -r
                d[lo] = e[lo] / (p + r)
                d[lo + 1] = e[lo] * (p + r)
                dlo1 = d[lo + 1]
                h = g - d[lo]
                for i in range(lo + 2, n):
                    d[i] -= h
                f += h
                p = d[m]
                c = 1.0
                c2 = c
                c3 = c
                elo1 = e[lo + 1]
                s = 0.0
                s2 = 0.0
                for i in range(m - 1, lo - 1, -1):
                    c3 = c2
                    c2 = c
                    s2 = s
                    g = c * e[i]
                    h = c * p
                    r = math.hypot(p, e[i])
                    e[i + 1] = s * r
                    s = e[i] / r
                    c = p / r
                    p = c * d[i] - s * g
                    d[i + 1] = h + s * (c * g + s * d[i])
                    for k in range(n):
                        h = V[k, i + 1]
                        V[k, i + 1] = s * V[k, i] + c * h
                        V[k, i] = c * V[k, i] - s * h
                p = -s * s2 * c3 * elo1 * e[lo] / dlo1
                e[lo] = s * p
                d[lo] = c * p
                if not abs(e[lo]) > eps * tst1:
                    break
        d[lo] = d[lo] + f
        e[lo] = 0.0
    return True


@njit(cache=True)
def psd_project(h, out, V, d, e):  # pragma: no cover - compiled
    """``out`` = ``h`` (n, n, symmetric) with its negative eigenvalues dropped; ``out`` may be
    ``h`` itself. ``V`` (n, n), ``d`` and ``e`` (n,) are work arrays."""
    n = h.shape[0]
    finite = True
    for i in range(n):
        for j in range(n):
            V[i, j] = h[i, j]
            finite = finite and np.isfinite(h[i, j])
    ok = False
    if finite:
        _tridiagonalize(V, d, e)
        ok = _ql_implicit(V, d, e)
    if not ok:  # not finite or not converged: LAPACK decides (and raises on non-finite input)
        vals, vecs = np.linalg.eigh(h)
        for k in range(n):
            d[k] = vals[k]
            for i in range(n):
                V[i, k] = vecs[i, k]
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.0
    for k in range(n):
        if d[k] > 0.0:
            for i in range(n):
                for j in range(n):
                    out[i, j] += d[k] * (V[i, k] * V[j, k])


@njit(cache=True)
def psd_project_in(h, out, Q, QH, V, d, e):  # pragma: no cover - compiled
    """``out`` = the projection of ``h`` (n, n, symmetric) when the orthonormal columns of
    ``Q`` (n, k) span its range: ``Q (Qᵀ h Q)₊ Qᵀ``, the eigen-decomposition done on the
    k x k matrix ``Qᵀ h Q`` (``h = Q Qᵀ h Q Qᵀ``, so both have the same non-zero eigenvalues and
    the eigenvectors of ``h`` are ``Q`` times those of the small one). ``QH`` (k, n), ``V``
    (k, k), ``d`` and ``e`` (k,) are work arrays; ``out`` must not be ``h``. Returns False
    (``out`` not written) when ``h`` is not finite or an eigenvalue does not converge."""
    n, k = Q.shape
    for a in range(k):
        for j in range(n):
            t = 0.0
            for i in range(n):
                t += Q[i, a] * h[i, j]
            QH[a, j] = t
    finite = True
    for a in range(k):
        for b in range(a, k):
            t = 0.0
            for j in range(n):
                t += QH[a, j] * Q[j, b]
            V[a, b] = t
            V[b, a] = t
            finite = finite and np.isfinite(t)
    if not finite:
        return False
    _tridiagonalize(V, d, e)
    if not _ql_implicit(V, d, e):
        return False
    for i in range(n):
        for j in range(n):
            out[i, j] = 0.0
    for c in range(k):
        if d[c] > 0.0:
            for i in range(n):  # the eigenvector in the full space, into row c of QH
                t = 0.0
                for a in range(k):
                    t += Q[i, a] * V[a, c]
                QH[c, i] = t
            for i in range(n):
                for j in range(n):
                    out[i, j] += d[c] * (QH[c, i] * QH[c, j])
    return True
