r"""The smoothly clamped log barrier on the squared distance offset by the thickness (compiled).

Symbols: centre-line distance ``d`` of a pair, contact distance :math:`d_{min} = r_a + r_b`
(the two radii; the filament radius alone against a floor), activation distance
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

from rotomorph.contact.distance import segment_distance2


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
def _psd_project(h):  # pragma: no cover - compiled
    vals, vecs = np.linalg.eigh(h)
    out = np.zeros_like(h)
    for k in range(vals.shape[0]):
        if vals[k] > 0.0:
            v = vecs[:, k]
            out += vals[k] * np.outer(v, v)
    return out


@njit(cache=True)
def pair_barrier(
    x, pairs, dmin, weight, dhat, kappa, need_grad, need_hess, grad, hloc, dist
):  # pragma: no cover - compiled
    """Barrier energy of segment pairs ``pairs`` (P, 4) = node indices ``p0, p1, q0, q1`` of
    ``x`` (M, 3) (a sphere repeats its centre as ``q0 = q1``).

    Adds gradients to ``grad`` (M, 3); writes local Hessians ``hloc`` (P, 12, 12) when
    ``need_hess`` is 1 (exact) or 2 (projected to positive semidefinite); writes each pair's
    centre-line distance to ``dist`` (P,). Returns inf when any pair touches.
    """
    energy = 0.0
    g = np.empty(12)
    h = np.empty((12, 12))
    for p in range(pairs.shape[0]):
        i0, i1, j0, j1 = pairs[p, 0], pairs[p, 1], pairs[p, 2], pairs[p, 3]
        D = segment_distance2(x[i0], x[i1], x[j0], x[j1], need_hess > 0, g, h)
        dist[p] = np.sqrt(D)
        zhat = (2.0 * dmin[p] + dhat) * dhat
        b, b1, b2 = barrier(D - dmin[p] * dmin[p], zhat)
        if b == 0.0 and b1 == 0.0:
            if need_hess:
                hloc[p] = 0.0
            continue
        if not np.isfinite(b):
            return np.inf
        c = kappa * weight[p]
        energy += c * b
        if need_grad:
            idx = (i0, i1, j0, j1)
            for n in range(4):
                for k in range(3):
                    grad[idx[n], k] += c * b1 * g[3 * n + k]
        if need_hess:
            for i in range(12):
                for j in range(12):
                    hloc[p, i, j] = c * (b2 * g[i] * g[j] + b1 * h[i, j])
            if need_hess == 2:
                hloc[p] = _psd_project(hloc[p])
    return energy


@njit(cache=True)
def plane_barrier(
    x, nodes, normal, offset, dmin, weight, dhat, kappa, need_grad, need_hess, grad, hloc, dist
):  # pragma: no cover - compiled
    """Barrier of nodes ``nodes`` (K,) above the plane ``normal . x = offset``.

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
