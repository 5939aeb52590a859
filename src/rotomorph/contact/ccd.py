r"""Collision-free step bounds by additive conservative advancement (compiled).

Along the straight path :math:`x(t) = x_0 + t\,\Delta x`, the distance between a point of
segment P and a point of segment Q changes at most by the largest relative motion of their
nodes: subtracting the pair's mean node displacement ``m`` (which moves both alike),
:math:`|\dot d| \le l_P + l_Q` with :math:`l_P = \max_{k \in P} |\Delta x_k - m|` (every point
of a segment is a convex combination of its end nodes). From a gap ``g = d − d_min`` the pair
therefore cannot touch within :math:`\delta t < g / (l_P + l_Q)`. Advancing by a fraction of
that and re-measuring the gap is the additive CCD of Li, Kaufman & Jiang, "Codimensional
Incremental Potential Contact", ACM TOG 40(4) 170 (2021), Alg. 1: every ``t`` it returns is
provably collision-free (not an estimate). A node against a plane moves linearly in height,
so its time of impact is exact.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph.contact.distance import BOUND_MARGIN, distance_bound, moving_distance2

ADVANCE = 0.9  # fraction of the provably safe advance taken per sub-step


@njit(cache=True)
def _distance(x0, dx, t, i0, i1, j0, j1):  # pragma: no cover - compiled
    return np.sqrt(moving_distance2(x0, dx, t, i0, i1, j0, j1))


@njit(cache=True)
def pair_step_bound(x0, dx, pairs, dmin, close_fraction, max_substeps, dist0):  # pragma: no cover
    """Largest ``t`` in [0, 1] such that no pair comes within ``dmin`` on ``[0, t]``.

    A pair stops the advance once it has closed ``close_fraction`` of its initial gap
    (``close_fraction = 1``: only contact or ``max_substeps`` stop it). Returns 0 when a pair
    starts at or inside contact. Pairs are advanced in the order of their first safe advance,
    so the bound falls early and the pairs that cannot close before it are skipped (the bound
    is the smallest stopping time over the pairs, whatever the order).

    ``dist0`` (P,): each pair's distance at ``x0`` where known, NaN where not; the distances
    this call needs are computed and stored there, so steps from the same ``x0`` over the same
    pairs (a line search's path checks) reuse them.
    """
    P = pairs.shape[0]
    gap0 = np.empty(P)
    rate = np.empty(P)
    first = np.empty(P)
    for p in range(P):
        i0, i1, j0, j1 = pairs[p, 0], pairs[p, 1], pairs[p, 2], pairs[p, 3]
        # scalars, not array expressions (those allocate temporaries per pair)
        m0 = (dx[i0, 0] + dx[i1, 0] + dx[j0, 0] + dx[j1, 0]) / 4.0
        m1 = (dx[i0, 1] + dx[i1, 1] + dx[j0, 1] + dx[j1, 1]) / 4.0
        m2 = (dx[i0, 2] + dx[i1, 2] + dx[j0, 2] + dx[j1, 2]) / 4.0
        lp = 0.0
        lq = 0.0
        for n in range(4):
            k = pairs[p, n]
            v0 = dx[k, 0] - m0
            v1 = dx[k, 1] - m1
            v2 = dx[k, 2] - m2
            ln = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
            if n < 2:
                lp = max(lp, ln)
            else:
                lq = max(lq, ln)
        rate[p] = lp + lq
        bound = distance_bound(x0, i0, i1, j0, j1) - dmin[p]
        if bound > 0.0 and ADVANCE * bound >= (1.0 + BOUND_MARGIN) * rate[p]:
            gap0[p] = bound  # cannot close even its first advance within the whole step
            first[p] = np.inf
            continue
        if np.isnan(dist0[p]):
            dist0[p] = _distance(x0, dx, 0.0, i0, i1, j0, j1)  # the same at t = 0 for any dx
        gap0[p] = dist0[p] - dmin[p]
        if gap0[p] <= 0.0:
            return 0.0
        first[p] = ADVANCE * gap0[p] / rate[p] if rate[p] > 0.0 else np.inf
    tmin = 1.0
    closing = np.flatnonzero(first < tmin)  # the others cannot close within the whole step
    for p in closing[np.argsort(first[closing])]:
        if first[p] >= tmin:
            break  # this pair and all after it cannot close within the current bound
        i0, i1, j0, j1 = pairs[p, 0], pairs[p, 1], pairs[p, 2], pairs[p, 3]
        t = 0.0
        gap = gap0[p]
        for _ in range(max_substeps):
            dt = ADVANCE * gap / rate[p]
            if t + dt >= tmin:
                t = tmin
                break
            t += dt
            gap = _distance(x0, dx, t, i0, i1, j0, j1) - dmin[p]
            if gap <= (1.0 - close_fraction) * gap0[p]:
                break
        tmin = min(tmin, t)
    return tmin


@njit(cache=True)
def plane_step_bound(x0, dx, nodes, normal, offset, dmin, close_fraction):  # pragma: no cover
    """Largest ``t`` in [0, 1] keeping every node's height above the plane ``> dmin``."""
    tmin = 1.0
    for p in range(nodes.shape[0]):
        i = nodes[p]
        h = normal[0] * x0[i, 0] + normal[1] * x0[i, 1] + normal[2] * x0[i, 2] - offset
        v = normal[0] * dx[i, 0] + normal[1] * dx[i, 1] + normal[2] * dx[i, 2]
        gap = h - dmin[p]
        if gap <= 0.0:
            return 0.0
        if v >= 0.0:
            continue
        hit = gap / -v  # exact time of touching
        tmin = min(tmin, close_fraction * hit if close_fraction < 1.0 else hit * (1.0 - 1e-12))
    return tmin
