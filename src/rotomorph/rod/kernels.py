r"""Compiled per-stencil energy kernels of discrete elastic rods.

One bend–twist stencil couples two edges that meet at a node: an *incoming* edge
:math:`e = x_1 - x_0` and an *outgoing* edge :math:`f = x_2 - x_1` with their material
directors and twist angles. Local degree-of-freedom order (11 entries)::

    [x0 (0:3), theta_e (3), x1 (4:7), theta_f (7), x2 (8:11)]

Energy of a stencil (the paper's :math:`E_\mathrm{discrete}` with separate bending stiffnesses):

.. math::

    E = \frac{1}{2\bar l}\left[B_1(\kappa_1-\bar\kappa_1)^2 + B_2(\kappa_2-\bar\kappa_2)^2
        + C(\tau-\bar\tau)^2\right]

with integrated curvatures :math:`\kappa_1 = \tfrac12 (\kappa b)\cdot(m_2^e+m_2^f)`,
:math:`\kappa_2 = -\tfrac12 (\kappa b)\cdot(m_1^e+m_1^f)` and twist
:math:`\tau = \theta_f - \theta_e + m_\mathrm{ref}` (Bergou et al. 2008, 2010).

Gradients and Hessians are the closed forms of Jawed, Novelia & O'Reilly, *A Primer on the
Kinematics of Discrete Elastic Rods* (Springer, 2018), §§ 7–8 (the same expressions are used in
disMech, Choi et al. 2024). With frames re-based at every iterate (time-parallel transport), the
symmetric part of these Hessians is the exact Hessian of the energy; the test-suite checks every
term against central finite differences.

Symbols: ``te, tf`` unit tangents, ``ne, nf`` edge lengths (mm), ``chi = 1 + te.tf``,
``tt = (te+tf)/chi``, ``d1t = (m1e+m1f)/chi``, ``d2t = (m2e+m2f)/chi``, ``kb`` the curvature
binormal.
"""

from __future__ import annotations

import numpy as np
from numba import njit

#: Compiled machine code is cached on disk (``__pycache__``): only the first run compiles.
#: The small helpers below are *not* inlined by numba (``inline="always"``): inlining them at
#: every call site made type inference of the stencil kernels about half of the whole first-run
#: compile time, while LLVM still inlines them in the machine code (measured: first filament
#: solve 30.6 s -> 19.4 s CPU cold; objective evaluation at N = 10 001 unchanged, 15-19 ms).
_CACHE = True


@njit(cache=_CACHE)
def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=_CACHE)
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=_CACHE)
def _lin(ca, a, cb, b):
    """ca * a + cb * b for 3-tuples."""
    return (ca * a[0] + cb * b[0], ca * a[1] + cb * b[1], ca * a[2] + cb * b[2])


@njit(cache=_CACHE)
def _row(arr, i):
    return (arr[i, 0], arr[i, 1], arr[i, 2])


@njit(cache=_CACHE)
def _clear(M, k):
    for i in range(3):
        for j in range(3):
            M[k, i, j] = 0.0


@njit(cache=_CACHE)
def _outer(M, k, c, a, b, sym):
    """M[k] += c * a b^T (+ c * b a^T when sym)."""
    for i in range(3):
        for j in range(3):
            v = a[i] * b[j]
            if sym:
                v += b[i] * a[j]
            M[k, i, j] += c * v


@njit(cache=_CACHE)
def _cross_matrix(M, k, c, a):
    """M[k] += c * [a]_x  (so that [a]_x v = a x v)."""
    M[k, 0, 1] -= c * a[2]
    M[k, 0, 2] += c * a[1]
    M[k, 1, 0] += c * a[2]
    M[k, 1, 2] -= c * a[0]
    M[k, 2, 0] -= c * a[1]
    M[k, 2, 1] += c * a[0]


@njit(cache=_CACHE)
def _identity(M, k, c):
    for i in range(3):
        M[k, i, i] += c


@njit(cache=_CACHE)
def _place_edge_blocks(H, w, D):
    """H += w * second derivatives wrt (x0, x1, x2) from D[0] = d2/de2, D[1] = d2/df2,
    D[2] = d2/de df."""
    for i in range(3):
        for j in range(3):
            ee = D[0, i, j]
            ff = D[1, i, j]
            ef = D[2, i, j]
            fe = D[2, j, i]
            H[i, j] += w * ee
            H[i, 4 + j] += w * (-ee + ef)
            H[i, 8 + j] += w * (-ef)
            H[4 + i, j] += w * (-ee + fe)
            H[4 + i, 4 + j] += w * (ee - ef - fe + ff)
            H[4 + i, 8 + j] += w * (ef - ff)
            H[8 + i, j] += w * (-fe)
            H[8 + i, 4 + j] += w * (fe - ff)
            H[8 + i, 8 + j] += w * ff


@njit(cache=_CACHE)
def _place_theta(H, w, col, De, Df):
    """H[x, col] and H[col, x] += w * mixed derivatives from d/de d/dtheta and d/df d/dtheta."""
    for i in range(3):
        a = -De[i]
        b = De[i] - Df[i]
        c = Df[i]
        H[i, col] += w * a
        H[col, i] += w * a
        H[4 + i, col] += w * b
        H[col, 4 + i] += w * b
        H[8 + i, col] += w * c
        H[col, 8 + i] += w * c


@njit(cache=_CACHE, inline="always")
def bend_measures(x0, x1, x2, m1e, m2e, m1f, m2f):
    """Edge lengths ``ne, nf`` (mm), unit tangents ``te, tf``, ``chi``, curvature binormal
    ``kb`` and integrated curvatures ``kappa1, kappa2`` of one stencil (arguments as for
    :func:`bend_twist_stencil`)."""
    e = (x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2])
    f = (x2[0] - x1[0], x2[1] - x1[1], x2[2] - x1[2])
    ne = np.sqrt(_dot(e, e))
    nf = np.sqrt(_dot(f, f))
    te = _lin(1.0 / ne, e, 0.0, e)
    tf = _lin(1.0 / nf, f, 0.0, f)
    chi = 1.0 + _dot(te, tf)
    kb = _lin(2.0 / chi, _cross(te, tf), 0.0, e)
    kappa1 = 0.5 * (_dot(kb, m2e) + _dot(kb, m2f))
    kappa2 = -0.5 * (_dot(kb, m1e) + _dot(kb, m1f))
    return ne, nf, te, tf, chi, kb, kappa1, kappa2


@njit(cache=_CACHE, inline="always")
def bend_twist_energy(kappa1, kappa2, twist, B1, B2, C, voronoi, k1bar, k2bar, taubar):
    """Energy of one stencil (N mm) from its curvatures and twist, with the strains
    ``kappa1 - k1bar``, ``kappa2 - k2bar``, ``twist - taubar`` and ``1 / voronoi``."""
    dk1 = kappa1 - k1bar
    dk2 = kappa2 - k2bar
    dtw = twist - taubar
    inv_l = 1.0 / voronoi
    energy = 0.5 * inv_l * (B1 * dk1 * dk1 + B2 * dk2 * dk2 + C * dtw * dtw)
    return energy, dk1, dk2, dtw, inv_l


@njit(cache=_CACHE)
def bend_twist_stencil(
    x0,
    x1,
    x2,
    m1e,
    m2e,
    m1f,
    m2f,
    twist,
    B1,
    B2,
    C,
    voronoi,
    k1bar,
    k2bar,
    taubar,
    grad,
    hess,
    need_grad,
    need_hess,
    D,
    gk,
):
    """Energy (N mm), gradient and Hessian of one bend-twist stencil.

    Vectors ``x0, x1, x2, m1e, m2e, m1f, m2f`` are 3-tuples (``m2`` already in the stencil's
    orientation). ``twist`` is the current integrated twist ``theta_f - theta_e + m_ref`` (rad);
    natural values are integrated (dimensionless). ``grad`` (11,) and ``hess`` (11, 11) are
    overwritten when requested; ``D`` (3, 3, 3) and ``gk`` (3, 11) are work buffers.
    ``need_hess`` 1 gives the exact Hessian, 2 its Gauss–Newton part
    ``sum_k w_k grad(k) grad(k)^T`` (positive semidefinite, used where the exact Hessian is
    indefinite). Returns ``(energy, kappa1, kappa2)``.
    """
    ne, nf, te, tf, chi, kb, kappa1, kappa2 = bend_measures(x0, x1, x2, m1e, m2e, m1f, m2f)
    energy, dk1, dk2, dtw, inv_l = bend_twist_energy(
        kappa1, kappa2, twist, B1, B2, C, voronoi, k1bar, k2bar, taubar
    )
    if not (need_grad or need_hess):
        return energy, kappa1, kappa2

    ic = 1.0 / chi
    tt = _lin(ic, te, ic, tf)
    d1t = _lin(ic, m1e, ic, m1f)
    d2t = _lin(ic, m2e, ic, m2f)
    tf_d2 = _cross(tf, d2t)
    te_d2 = _cross(te, d2t)
    tf_d1 = _cross(tf, d1t)
    te_d1 = _cross(te, d1t)
    g1e = _lin(-kappa1 / ne, tt, 1.0 / ne, tf_d2)
    g1f = _lin(-kappa1 / nf, tt, -1.0 / nf, te_d2)
    g2e = _lin(-kappa2 / ne, tt, -1.0 / ne, tf_d1)
    g2f = _lin(-kappa2 / nf, tt, 1.0 / nf, te_d1)
    for i in range(3):
        gk[0, i] = -g1e[i]
        gk[0, 4 + i] = g1e[i] - g1f[i]
        gk[0, 8 + i] = g1f[i]
        gk[1, i] = -g2e[i]
        gk[1, 4 + i] = g2e[i] - g2f[i]
        gk[1, 8 + i] = g2f[i]
        gk[2, i] = -0.5 * kb[i] / ne
        gk[2, 8 + i] = 0.5 * kb[i] / nf
        gk[2, 4 + i] = -(gk[2, i] + gk[2, 8 + i])
    gk[0, 3] = -0.5 * _dot(kb, m1e)
    gk[0, 7] = -0.5 * _dot(kb, m1f)
    gk[1, 3] = -0.5 * _dot(kb, m2e)
    gk[1, 7] = -0.5 * _dot(kb, m2f)
    gk[2, 3] = -1.0
    gk[2, 7] = 1.0
    a1 = inv_l * B1 * dk1
    a2 = inv_l * B2 * dk2
    a3 = inv_l * C * dtw
    if need_grad:
        for k in range(11):
            grad[k] = a1 * gk[0, k] + a2 * gk[1, k] + a3 * gk[2, k]
    if not need_hess:
        return energy, kappa1, kappa2

    w1 = inv_l * B1
    w2 = inv_l * B2
    w3 = inv_l * C
    for i in range(11):
        for j in range(11):
            hess[i, j] = (
                w1 * gk[0, i] * gk[0, j] + w2 * gk[1, i] * gk[1, j] + w3 * gk[2, i] * gk[2, j]
            )
    if need_hess == 2:
        return energy, kappa1, kappa2
    # indices and flags as plain (non-literal) values: numba compiles a helper once per literal
    # argument value otherwise (13 compiled specialisations of 5 helpers instead of 5)
    i0, i1, i2 = np.int64(0), np.int64(1), np.int64(2)
    col_e, col_f = np.int64(3), np.int64(7)
    sym, plain = np.bool_(True), np.bool_(False)
    ne2 = ne * ne
    nf2 = nf * nf
    nef = ne * nf
    # ---- kappa1 second derivatives (Jawed, Novelia & O'Reilly 2018, Sec. 7) ----
    if a1 != 0.0:
        _clear(D, i0)
        _clear(D, i1)
        _clear(D, i2)
        _outer(D, i0, 2.0 * kappa1 / ne2, tt, tt, plain)
        _outer(D, i0, -1.0 / ne2, tf_d2, tt, sym)
        _identity(D, i0, -kappa1 / (chi * ne2))
        _outer(D, i0, kappa1 / (chi * ne2), te, te, plain)
        _outer(D, i0, 0.25 / ne2, kb, m2e, sym)
        _outer(D, i1, 2.0 * kappa1 / nf2, tt, tt, plain)
        _outer(D, i1, 1.0 / nf2, te_d2, tt, sym)
        _identity(D, i1, -kappa1 / (chi * nf2))
        _outer(D, i1, kappa1 / (chi * nf2), tf, tf, plain)
        _outer(D, i1, 0.25 / nf2, kb, m2f, sym)
        _identity(D, i2, -kappa1 / (chi * nef))
        _outer(D, i2, -kappa1 / (chi * nef), te, tf, plain)
        _outer(D, i2, 2.0 * kappa1 / nef, tt, tt, plain)
        _outer(D, i2, -1.0 / nef, tf_d2, tt, plain)
        _outer(D, i2, 1.0 / nef, tt, te_d2, plain)
        _cross_matrix(D, i2, -1.0 / nef, d2t)
        _place_edge_blocks(hess, a1, D)
        hess[3, 3] += a1 * (-0.5 * _dot(kb, m2e))
        hess[7, 7] += a1 * (-0.5 * _dot(kb, m2f))
        c = 0.5 * _dot(kb, m1e)
        _place_theta(
            hess,
            a1,
            col_e,
            _lin(c / ne, tt, -ic / ne, _cross(tf, m1e)),
            _lin(c / nf, tt, ic / nf, _cross(te, m1e)),
        )
        c = 0.5 * _dot(kb, m1f)
        _place_theta(
            hess,
            a1,
            col_f,
            _lin(c / ne, tt, -ic / ne, _cross(tf, m1f)),
            _lin(c / nf, tt, ic / nf, _cross(te, m1f)),
        )
    # ---- kappa2 second derivatives ----
    if a2 != 0.0:
        _clear(D, i0)
        _clear(D, i1)
        _clear(D, i2)
        _outer(D, i0, 2.0 * kappa2 / ne2, tt, tt, plain)
        _outer(D, i0, 1.0 / ne2, tf_d1, tt, sym)
        _identity(D, i0, -kappa2 / (chi * ne2))
        _outer(D, i0, kappa2 / (chi * ne2), te, te, plain)
        _outer(D, i0, -0.25 / ne2, kb, m1e, sym)
        _outer(D, i1, 2.0 * kappa2 / nf2, tt, tt, plain)
        _outer(D, i1, -1.0 / nf2, te_d1, tt, sym)
        _identity(D, i1, -kappa2 / (chi * nf2))
        _outer(D, i1, kappa2 / (chi * nf2), tf, tf, plain)
        _outer(D, i1, -0.25 / nf2, kb, m1f, sym)
        _identity(D, i2, -kappa2 / (chi * nef))
        _outer(D, i2, -kappa2 / (chi * nef), te, tf, plain)
        _outer(D, i2, 2.0 * kappa2 / nef, tt, tt, plain)
        _outer(D, i2, 1.0 / nef, tf_d1, tt, plain)
        _outer(D, i2, -1.0 / nef, tt, te_d1, plain)
        _cross_matrix(D, i2, 1.0 / nef, d1t)
        _place_edge_blocks(hess, a2, D)
        hess[3, 3] += a2 * (0.5 * _dot(kb, m1e))
        hess[7, 7] += a2 * (0.5 * _dot(kb, m1f))
        c = 0.5 * _dot(kb, m2e)
        _place_theta(
            hess,
            a2,
            col_e,
            _lin(c / ne, tt, -ic / ne, _cross(tf, m2e)),
            _lin(c / nf, tt, ic / nf, _cross(te, m2e)),
        )
        c = 0.5 * _dot(kb, m2f)
        _place_theta(
            hess,
            a2,
            col_f,
            _lin(c / ne, tt, -ic / ne, _cross(tf, m2f)),
            _lin(c / nf, tt, ic / nf, _cross(te, m2f)),
        )
    # ---- twist (reference twist) second derivatives ----
    if a3 != 0.0:
        _clear(D, i0)
        _clear(D, i1)
        _clear(D, i2)
        _outer(D, i0, -0.25 / ne2, kb, _lin(1.0, te, 1.0, tt), sym)
        _outer(D, i1, -0.25 / nf2, kb, _lin(1.0, tf, 1.0, tt), sym)
        _cross_matrix(D, i2, 1.0 / (chi * nef), te)
        _outer(D, i2, -0.5 / nef, kb, tt, plain)
        _place_edge_blocks(hess, a3, D)
    # The blocks are placed symmetrically (d2/de df and its transpose), so ``hess`` is the
    # symmetric part of the Jacobian of the gradient: the exact Hessian with re-based frames.
    return energy, kappa1, kappa2


@njit(cache=_CACHE, inline="always")
def stretch_energy(length, axial_stiffness, rest_length):
    """Stretching energy of an edge of ``length`` (mm), with ``EA / l`` and ``|e| - l``."""
    k = axial_stiffness / rest_length
    dl = length - rest_length
    return 0.5 * k * dl * dl, k, dl


@njit(cache=_CACHE)
def stretch_edge(xi, xj, axial_stiffness, rest_length, grad, hess, need_grad, need_hess):
    r"""Stretching energy :math:`\tfrac12 (EA/\bar l)(|e|-\bar l)^2` of one edge (N mm).

    Local order ``[xi (0:3), xj (3:6)]``; ``grad`` (6,) and ``hess`` (6, 6) are overwritten.
    ``need_hess`` 2 drops the (indefinite under compression) transverse term.
    """
    e0 = xj[0] - xi[0]
    e1 = xj[1] - xi[1]
    e2 = xj[2] - xi[2]
    n = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
    energy, k, dl = stretch_energy(n, axial_stiffness, rest_length)
    if need_grad or need_hess:
        t0 = e0 / n
        t1 = e1 / n
        t2 = e2 / n
        if need_grad:
            c = k * dl
            grad[0] = -c * t0
            grad[1] = -c * t1
            grad[2] = -c * t2
            grad[3] = c * t0
            grad[4] = c * t1
            grad[5] = c * t2
        if need_hess:
            t = np.empty(3)
            t[0], t[1], t[2] = t0, t1, t2
            r = dl / n
            if need_hess == 2:
                r = max(r, 0.0)
            for i in range(3):
                for j in range(3):
                    v = k * ((1.0 - r) * t[i] * t[j] + (r if i == j else 0.0))
                    hess[i, j] = v
                    hess[3 + i, 3 + j] = v
                    hess[i, 3 + j] = -v
                    hess[3 + i, j] = -v
    return energy
