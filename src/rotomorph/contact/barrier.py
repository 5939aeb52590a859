r"""The smoothly clamped log barrier on the squared distance offset by the thickness (compiled).

Symbols: centre-line distance ``d`` of a pair, :math:`d_{min}` the distance at which the barrier
is infinite (the contact distance :math:`r_a + r_b`, or the filament radius alone against a
floor, less the contact offset: :mod:`rotomorph.contact.potential` puts the zone inside the
contact distance, so that it ends where the surfaces touch), activation distance
:math:`\hat d` (the barrier is zero for :math:`d \ge d_{min} + \hat d`). On the offset squared
distance :math:`z = d^2 - d_{min}^2` with activation :math:`\hat z = (2 d_{min} + \hat d)\hat d`,

.. math::  b(z) = -(z - \hat z)^2 \ln(z / \hat z) \quad (0 < z < \hat z),
           \qquad b(z) = 0 \quad (z \ge \hat z),

which is C² at :math:`\hat z` and tends to +∞ as the surfaces touch (``z → 0``): Li et al.,
"Incremental Potential Contact", ACM TOG 39(4) 49 (2020), eq. (6); the thickness offset on the
squared distance is the codimensional form of Li, Kaufman & Jiang, "Codimensional Incremental
Potential Contact", ACM TOG 40(4) 170 (2021), § 4. A pair's energy is
:math:`\kappa\, w\, b(z)` with a length weight ``w`` (mm) so that the barrier is a line density
and does not change with the mesh. Units: ``z`` mm², ``b`` mm⁴, ``κ`` N/mm⁵, energy N mm.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph.contact.distance import (
    BOUND_MARGIN,
    closest_terms,
    distance_bound,
    pair_distance2,
    segment_distance2,
)
from rotomorph.contact.psd import psd_project, psd_project_in


@njit(cache=True)
def barrier(z, zhat):  # pragma: no cover - compiled
    """``(b, b', b'')`` of the clamped log barrier at ``z`` (inf for ``z <= 0``)."""
    if z >= zhat:
        return 0.0, 0.0, 0.0
    if z <= 0.0:
        return np.inf, -np.inf, np.inf
    dz = z - zhat
    lg = np.log(z / zhat)
    b = -dz * dz * lg
    b1 = -2.0 * dz * lg - dz * dz / z
    b2 = -2.0 * lg - 4.0 * dz / z + dz * dz / (z * z)
    return b, b1, b2


@njit(cache=True)
def mollifier(c, eps):  # pragma: no cover - compiled
    """``(m, m', m'')`` of IPC's edge–edge mollifier at ``c = |a x b|^2`` (Li et al. 2020,
    eq. 10): ``m = (2 - c / eps) c / eps`` below ``eps``, 1 beyond (C¹ at ``eps``)."""
    if c >= eps:
        return 1.0, 0.0, 0.0
    r = c / eps
    return (2.0 - r) * r, (2.0 - 2.0 * r) / eps, -2.0 / (eps * eps)


@njit(cache=True)
def cross_norm2(p0, p1, q0, q1, need_hess, grad, hess):  # pragma: no cover - compiled
    """``|a x b|^2 = |a|^2 |b|^2 - (a.b)^2`` of ``a = p1 - p0``, ``b = q1 - q0``; gradient (12,)
    and, if ``need_hess``, Hessian (12, 12) in the order ``p0, p1, q0, q1``."""
    a = p1 - p0
    b = q1 - q0
    A = a @ a
    E = b @ b
    B = a @ b
    ga = 2.0 * E * a - 2.0 * B * b
    gb = 2.0 * A * b - 2.0 * B * a
    for k in range(3):
        grad[k] = -ga[k]
        grad[3 + k] = ga[k]
        grad[6 + k] = -gb[k]
        grad[9 + k] = gb[k]
    if need_hess:
        sa = (-1.0, 1.0)
        for u in range(3):
            for v in range(3):
                eye = 1.0 if u == v else 0.0
                haa = 2.0 * E * eye - 2.0 * b[u] * b[v]
                hbb = 2.0 * A * eye - 2.0 * a[u] * a[v]
                hab = 4.0 * a[u] * b[v] - 2.0 * b[u] * a[v] - 2.0 * B * eye
                for m in range(2):
                    for n in range(2):
                        sg = sa[m] * sa[n]
                        hess[3 * m + u, 3 * n + v] = sg * haa
                        hess[6 + 3 * m + u, 6 + 3 * n + v] = sg * hbb
                        hess[3 * m + u, 6 + 3 * n + v] = sg * hab
                        hess[6 + 3 * n + v, 3 * m + u] = sg * hab
    return A * E - B * B


@njit(cache=True)
def _add_column(Q, c, v, r):  # pragma: no cover - compiled
    """Column ``c`` of ``Q`` := ``v`` orthogonalized against columns ``0..c-1`` (orthonormal)
    twice (classical Gram–Schmidt with reorthogonalization) and normalized; when nothing of
    ``v`` is left, the first unit vector that leaves enough. ``r`` (n,): work."""
    n = Q.shape[0]
    for trial in range(n + 1):
        for i in range(n):
            r[i] = v[i] if trial == 0 else (1.0 if i == trial - 1 else 0.0)
        for _ in range(2):
            for j in range(c):
                t = 0.0
                for i in range(n):
                    t += Q[i, j] * r[i]
                for i in range(n):
                    r[i] -= t * Q[i, j]
        nr = 0.0
        for i in range(n):
            nr += r[i] * r[i]
        nr = np.sqrt(nr)
        if (trial == 0 and nr > 0.0) or nr > 0.5:
            for i in range(n):
                Q[i, c] = r[i] / nr
            return


@njit(cache=True)
def _project_unmollified(
    p0, p1, q0, q1, c, b1, b2, H, out, Q, QH, V4, V5, d, e, gs, gt, r
):  # pragma: no cover - compiled
    """``out`` = the positive semidefinite projection of ``H``, the barrier Hessian
    ``c (b'' g gᵀ + b' ∇²D)`` of a pair without mollifier term (``g = 2 w ⊗ r``), from the
    structure of ``∇²D`` (:mod:`rotomorph.contact.distance`: ``2 w wᵀ ⊗ I₃`` less a Schur
    complement in ``G_s`` and/or ``G_t`` when a closest-point parameter lies inside its
    segment; the same tests decide which):

    * no parameter inside (two points closest): ``H = c (w wᵀ) ⊗ (4 b'' r rᵀ + 2 b' I₃)`` has
      the eigenvalue ``c |w|² (4 b'' D + 2 b')`` on ``w ⊗ r`` and ``2 c |w|² b'`` on the two
      ``w ⊗ r⊥``, all others 0: the projection in closed form;
    * else ``H``'s range lies in the span of ``w ⊗ e_k`` (k = 1..3) and ``G_s``, ``G_t`` (4
      or 5 dimensions), where its eigen-decomposition is done (:func:`psd_project_in`).

    The same matrix as the eigen-decomposition of the whole 12 x 12 block, to round-off.
    ``Q`` (12, 5), ``QH`` (5, 12), ``V4``, ``V5``, ``d``, ``e`` (>= 5), ``gs``, ``gt``, ``r``
    (12,): work arrays. Returns False when the eigen-decomposition failed.
    """
    _, _, w, a, b, rr, _, _, s_free, t_free = closest_terms(p0, p1, q0, q1)
    if not (s_free or t_free):
        D = rr[0] * rr[0] + rr[1] * rr[1] + rr[2] * rr[2]
        along = c * max(4.0 * b2 * D + 2.0 * b1, 0.0) / D
        across = c * max(2.0 * b1, 0.0)
        for n in range(4):
            for m in range(4):
                ww = w[n] * w[m]
                for k in range(3):
                    for j in range(3):
                        v = along * ww * rr[k] * rr[j]
                        if across != 0.0:
                            v += across * ww * ((1.0 if k == j else 0.0) - rr[k] * rr[j] / D)
                        out[3 * n + k, 3 * m + j] = v
        return True
    cs = (-1.0, 1.0, 0.0, 0.0)
    ct = (0.0, 0.0, -1.0, 1.0)
    nw = np.sqrt(w[0] * w[0] + w[1] * w[1] + w[2] * w[2] + w[3] * w[3])
    for n in range(4):
        for k in range(3):
            gs[3 * n + k] = 2.0 * (w[n] * a[k] + cs[n] * rr[k])
            gt[3 * n + k] = -2.0 * (w[n] * b[k] + ct[n] * rr[k])
            for col in range(3):
                Q[3 * n + k, col] = w[n] / nw if col == k else 0.0
    k = 3
    if s_free:
        _add_column(Q, k, gs, r)
        k += 1
    if t_free:
        _add_column(Q, k, gt, r)
        k += 1
    V = V5 if k == 5 else V4
    return psd_project_in(H, out, Q[:, :k], QH[:k], V, d[:k], e[:k])


@njit(cache=True)
def pair_barrier(
    x, pairs, dmin, weight, mollify, dhat, kappa, need_grad, need_hess, grad, hloc, dist
):  # pragma: no cover - compiled
    """Barrier energy of segment pairs ``pairs`` (P, 4) = node indices ``p0, p1, q0, q1`` of
    ``x`` (M, 3); a point repeats its node (``p0 = p1`` for a node against a segment, ``q0 = q1``
    for a sphere's centre).

    Inactive pairs with ``dist >= dmin + dhat`` leave ``hloc`` unwritten.
    ``mollify`` (P,): IPC's mollifier threshold ``eps`` of edge–edge pairs (0: none). The
    distance of two segments has a kink where they are parallel and overlap (the closest points
    jump along the overlap); the mollifier fades the edge–edge term out there, and node–segment
    pairs (smooth) carry side-by-side contact. Adds gradients to ``grad`` (M, 3); writes local
    Hessians ``hloc`` (P, 12, 12) when ``need_hess`` is 1 (exact) or 2 (projected to positive
    semidefinite); writes each pair's centre-line distance to ``dist`` (P,) (for a pair
    clearly beyond ``dmin + dhat``: a lower bound on it, also beyond). Returns inf when any
    pair touches.
    """
    energy = 0.0
    no, yes = np.bool_(False), np.bool_(True)  # not literals: one compiled segment_distance2
    g = np.empty(12)
    h = np.empty((12, 12))
    gx = np.empty(12)
    hx = np.empty((12, 12))
    vecs = np.empty((12, 12))  # work arrays of the projection
    vals = np.empty(12)
    off = np.empty(12)
    q5 = np.empty((12, 5))  # the range of a Hessian without mollifier term
    qh = np.empty((5, 12))
    v4 = np.empty((4, 4))
    v5 = np.empty((5, 5))
    gs = np.empty(12)
    gt = np.empty(12)
    rw = np.empty(12)
    for p in range(pairs.shape[0]):
        i0, i1, j0, j1 = pairs[p, 0], pairs[p, 1], pairs[p, 2], pairs[p, 3]
        reach = dmin[p] + dhat
        bound = distance_bound(x, i0, i1, j0, j1)
        if bound > reach * (1.0 + BOUND_MARGIN):
            dist[p] = bound  # clearly out of reach: the distance itself is not needed
            continue
        D = pair_distance2(x, i0, i1, j0, j1)
        dist[p] = np.sqrt(D)
        if D >= reach * reach:
            continue  # inactive: zero energy, its hloc block is left unwritten
        if need_grad or need_hess:  # its gradient (D itself: the same value as above)
            D = segment_distance2(x[i0], x[i1], x[j0], x[j1], no, g, h)
        zhat = (2.0 * dmin[p] + dhat) * dhat
        b, b1, b2 = barrier(D - dmin[p] * dmin[p], zhat)
        if b == 0.0 and b1 == 0.0:
            if need_hess and dist[p] < dmin[p] + dhat:  # rounding at the activation edge
                hloc[p] = 0.0
            continue  # inactive: its hloc block is left unwritten
        if not np.isfinite(b):
            return np.inf
        if need_hess:  # active pair: now its Hessian
            segment_distance2(x[i0], x[i1], x[j0], x[j1], yes, g, h)
        m, m1, m2 = 1.0, 0.0, 0.0
        if mollify[p] > 0.0:
            cx = cross_norm2(x[i0], x[i1], x[j0], x[j1], need_hess > 0, gx, hx)
            m, m1, m2 = mollifier(cx, mollify[p])
        c = kappa * weight[p]
        energy += c * m * b
        if need_grad:
            idx = (i0, i1, j0, j1)
            for n in range(4):
                for k in range(3):
                    q = 3 * n + k
                    v = m * b1 * g[q]
                    if m1 != 0.0:
                        v += b * m1 * gx[q]
                    grad[idx[n], k] += c * v
        if need_hess:
            for i in range(12):
                for j in range(12):
                    v = m * (b2 * g[i] * g[j] + b1 * h[i, j])
                    if m1 != 0.0 or m2 != 0.0:
                        v += b1 * m1 * (g[i] * gx[j] + gx[i] * g[j])
                        v += b * (m2 * gx[i] * gx[j] + m1 * hx[i, j])
                    hloc[p, i, j] = c * v
            if need_hess == 2:
                ok = False
                if m1 == 0.0 and m2 == 0.0:  # from the Hessian's structure (4-5 dimensions)
                    vecs[:, :] = hloc[p]
                    ok = _project_unmollified(
                        x[i0], x[i1], x[j0], x[j1], c * m, b1, b2, vecs, hloc[p], q5, qh, v4,
                        v5, vals, off, gs, gt, rw,
                    )  # fmt: skip
                    if not ok:
                        hloc[p] = vecs
                if not ok:  # a mollifier term (or a failed projection): all 12 dimensions
                    psd_project(hloc[p], hloc[p], vecs, vals, off)
    return energy


@njit(cache=True)
def plane_barrier(
    x, nodes, normal, offset, dmin, weight, dhat, kappa, need_grad, need_hess, grad, hloc, dist
):  # pragma: no cover - compiled
    """Barrier of nodes ``nodes`` (K,) above the plane ``normal·x = offset``.

    The signed height ``h = normal . x - offset`` must exceed ``dmin`` (the radius): the barrier
    is taken on ``h^2 - dmin^2`` (inf when ``h <= dmin``, also below the plane). Local Hessians
    ``hloc`` (K, 3, 3); heights to ``dist``.
    """
    energy = 0.0
    for p in range(nodes.shape[0]):
        i = nodes[p]
        hgt = normal[0] * x[i, 0] + normal[1] * x[i, 1] + normal[2] * x[i, 2] - offset
        dist[p] = hgt
        if hgt <= dmin[p]:
            return np.inf
        zhat = (2.0 * dmin[p] + dhat) * dhat
        b, b1, b2 = barrier(hgt * hgt - dmin[p] * dmin[p], zhat)
        if b == 0.0 and b1 == 0.0:
            if need_hess:
                hloc[p] = 0.0
            continue
        c = kappa * weight[p]
        energy += c * b
        if need_grad:
            for k in range(3):
                grad[i, k] += c * b1 * 2.0 * hgt * normal[k]
        if need_hess:
            # d2(h^2) = 2 n n^T (convex), b'' > 0 and b' < 0 with h > 0: the 1-D second
            # derivative c (4 h^2 b'' + 2 b') is what matters; projecting clamps it at 0
            coef = c * (4.0 * hgt * hgt * b2 + 2.0 * b1)
            if need_hess == 2 and coef < 0.0:
                coef = 0.0
            for a in range(3):
                for k in range(3):
                    hloc[p, a, k] = coef * normal[a] * normal[k]
    return energy
