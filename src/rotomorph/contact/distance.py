r"""Squared distance between two segments with its exact gradient and Hessian (compiled).

Symbols (one pair, 12 coordinates): segment P from ``p0`` to ``p1``, segment Q from ``q0`` to
``q1``; closest points :math:`p(s) = p_0 + s\,a`, :math:`q(t) = q_0 + t\,b` with
:math:`a = p_1 - p_0`, :math:`b = q_1 - q_0`, :math:`(s, t) \in [0, 1]^2`. The squared distance
is the value of a box-constrained least-squares problem,

.. math::  D(x) = \min_{s,t} f(x, s, t), \qquad f = |r|^2, \quad r = p(s) - q(t)
           = \textstyle\sum_k w_k x_k, \quad w = (1-s,\ s,\ -(1-t),\ -t).

Gradient (envelope theorem): :math:`\partial D/\partial x_k = 2 w_k r`. Hessian: where the set of
parameters strictly inside ``(0, 1)`` (the free set F) does not change, implicit differentiation
of :math:`\partial f/\partial u_F = 0` gives the Schur complement

.. math::  \nabla^2 D = f_{xx} - f_{xu_F}\, f_{u_F u_F}^{-1}\, f_{u_F x},

with :math:`f_{xx} = 2\,w w^T \otimes I_3`,
:math:`\partial^2 f/\partial s\,\partial x_k = 2(w_k a + c^s_k r)`, :math:`c^s = (-1, 1, 0, 0)`,
:math:`\partial^2 f/\partial t\,\partial x_k = -2(w_k b + c^t_k r)`, :math:`c^t = (0, 0, -1, 1)`,
:math:`f_{uu} = 2\begin{pmatrix} a\cdot a & -a\cdot b \\ -a\cdot b & b\cdot b\end{pmatrix}`.
This covers all distance types at once: edge–edge (both free), point–edge (one free) and
point–point (none free); a zero-length Q (``q0 = q1``) is a point, which is how spheres enter.
The closest points are the interior stationary point when it lies inside the unit square, else
the best of the four edge minima (the problem is a convex quadratic); comparing all valid
candidates keeps ``D`` continuous through (nearly) parallel configurations, where a branch on a
parallelism threshold (Ericson, *Real-Time Collision Detection*, 2005, § 5.1.9) jumps by up to
``|a|^2 sin^2(angle)`` — enough for a stiff barrier to stall Newton's line search. The function
is C¹ across type changes and smooth within each type; exactly parallel overlapping segments
are a kink of the distance itself (any segment distance has it).
"""

from __future__ import annotations

import numpy as np
from numba import njit

PARALLEL = 1e-10  # relative |a x b|^2 below which segments count as parallel


@njit(cache=True)
def _clamp01(v):  # pragma: no cover - compiled
    return 0.0 if v < 0.0 else (1.0 if v > 1.0 else v)


@njit(cache=True)
def closest_parameters(p0, p1, q0, q1):  # pragma: no cover - compiled
    """Closest-point parameters ``(s, t)`` of segments ``p0p1`` and ``q0q1`` (each in [0, 1])."""
    A, B, C, E, F, R = _gram(p0, p1, q0, q1)
    return _closest_gram(A, B, C, E, F, R)


@njit(cache=True)
def _gram(p0, p1, q0, q1):  # pragma: no cover - compiled
    """Gram entries ``(A, B, C, E, F, R)`` of :func:`_closest_gram` from the end points (3-arrays
    or 3-tuples)."""
    A = 0.0
    B = 0.0
    C = 0.0
    E = 0.0
    F = 0.0
    R = 0.0
    for k in range(3):
        a = p1[k] - p0[k]
        b = q1[k] - q0[k]
        r = p0[k] - q0[k]
        R += r * r
        A += a * a
        B += a * b
        C += a * r
        E += b * b
        F += b * r
    return A, B, C, E, F, R


@njit(cache=True)
def pair_distance2(x, i0, i1, j0, j1):  # pragma: no cover - compiled
    """Squared distance of segments ``x[i0] x[i1]`` and ``x[j0] x[j1]`` (no allocation)."""
    return moving_distance2(x, x, 0.0, i0, i1, j0, j1)


@njit(cache=True)
def _moved(x, dx, t, i):  # pragma: no cover - compiled
    """Node ``i`` of ``x + t dx`` as a 3-tuple (no allocation)."""
    return (x[i, 0] + t * dx[i, 0], x[i, 1] + t * dx[i, 1], x[i, 2] + t * dx[i, 2])


@njit(cache=True)
def moving_distance2(x, dx, t, i0, i1, j0, j1):  # pragma: no cover - compiled
    """Squared distance of the segments of ``x + t dx`` (no allocation)."""
    p0 = _moved(x, dx, t, i0)
    p1 = _moved(x, dx, t, i1)
    q0 = _moved(x, dx, t, j0)
    q1 = _moved(x, dx, t, j1)
    s, u = closest_parameters(p0, p1, q0, q1)
    D = 0.0
    for k in range(3):
        a = p1[k] - p0[k]
        b = q1[k] - q0[k]
        r = p0[k] + s * a - q0[k] - u * b
        D += r * r
    return D


@njit(cache=True)
def _closest_gram(A, B, C, E, F, R):  # pragma: no cover - compiled
    """Closest-point parameters from the Gram entries of ``a = p1 - p0``, ``b = q1 - q0``,
    ``r = p0 - q0``: ``A = a.a, B = a.b, C = a.r, E = b.b, F = b.r, R = r.r``."""
    tiny = 1e-300
    if A <= tiny and E <= tiny:
        return 0.0, 0.0
    if A <= tiny:
        return 0.0, _clamp01(F / E)
    if E <= tiny:
        return _clamp01(-C / A), 0.0
    # the minimum of a convex quadratic over the unit square: the interior stationary point if
    # it lies inside, else the best of the four edge minima; taking the smallest of all valid
    # candidates keeps D continuous, also through (nearly) parallel configurations where the
    # interior point is ill-conditioned and skipped
    best_s, best_t = 0.0, _clamp01(F / E)
    best = _d2(A, B, C, E, F, best_s, best_t, R)
    for edge in range(3):
        if edge == 0:
            s, t = 1.0, _clamp01((B + F) / E)
        elif edge == 1:
            s, t = _clamp01(-C / A), 0.0
        else:
            s, t = _clamp01((B - C) / A), 1.0
        v = _d2(A, B, C, E, F, s, t, R)
        if v < best:
            best, best_s, best_t = v, s, t
    den = A * E - B * B
    if den > PARALLEL * A * E:
        s = (B * F - C * E) / den
        t = (A * F - B * C) / den
        if 0.0 < s < 1.0 and 0.0 < t < 1.0:
            v = _d2(A, B, C, E, F, s, t, R)
            if v <= best:
                best_s, best_t = s, t
    return best_s, best_t


@njit(cache=True)
def _d2(A, B, C, E, F, s, t, R):  # pragma: no cover - compiled
    """|r + s a - t b|^2 from the Gram entries (r = p0 - q0, R = |r|^2)."""
    return R + s * s * A + t * t * E - 2.0 * s * t * B + 2.0 * s * C - 2.0 * t * F


@njit(cache=True)
def closest_terms(p0, p1, q0, q1):  # pragma: no cover - compiled
    """The terms of :func:`segment_distance2` at the closest points, as scalars and tuples (no
    allocation): ``s, t, w, a, b, r, A, E, s_free, t_free`` with ``w = (1-s, s, -(1-t), -t)``,
    ``a = p1 - p0``, ``b = q1 - q0``, ``r = p(s) - q(t)``, ``A = a.a``, ``E = b.b`` and which
    parameters lie inside their segment (the free set of the Hessian; of two nearly parallel
    free ones, ``s`` is held at its end)."""
    s, t = closest_parameters(p0, p1, q0, q1)
    w = (1.0 - s, s, -(1.0 - t), -t)
    a0, a1, a2 = p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]
    b0, b1, b2 = q1[0] - q0[0], q1[1] - q0[1], q1[2] - q0[2]
    r = (
        p0[0] + s * a0 - q0[0] - t * b0,
        p0[1] + s * a1 - q0[1] - t * b1,
        p0[2] + s * a2 - q0[2] - t * b2,
    )
    A = a0 * a0 + a1 * a1 + a2 * a2
    E = b0 * b0 + b1 * b1 + b2 * b2
    Bab = a0 * b0 + a1 * b1 + a2 * b2
    s_free = A > 1e-300 and 0.0 < s < 1.0
    t_free = E > 1e-300 and 0.0 < t < 1.0
    if s_free and t_free and A * E - Bab * Bab <= PARALLEL * A * E:
        s_free = False  # parallel branch: s is held at its end
    return s, t, w, (a0, a1, a2), (b0, b1, b2), r, A, E, s_free, t_free


@njit(cache=True)
def segment_distance2(p0, p1, q0, q1, need_hess, grad, hess):  # pragma: no cover - compiled
    """Squared distance ``D``; fills ``grad`` (12,) and, if ``need_hess``, ``hess`` (12, 12).

    Coordinates are ordered ``p0, p1, q0, q1`` (3 each).
    """
    _, _, w, a, b, r, A, E, s_free, t_free = closest_terms(p0, p1, q0, q1)
    D = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    for n in range(4):
        for k in range(3):
            grad[3 * n + k] = 2.0 * w[n] * r[k]
    if not need_hess:
        return D
    for n in range(4):
        for m in range(4):
            for k in range(3):
                for j in range(3):
                    hess[3 * n + k, 3 * m + j] = 2.0 * w[n] * w[m] if k == j else 0.0
    if not (s_free or t_free):
        return D
    cs = (-1.0, 1.0, 0.0, 0.0)
    ct = (0.0, 0.0, -1.0, 1.0)
    Gs = np.empty(12)
    Gt = np.empty(12)
    for n in range(4):
        for k in range(3):
            Gs[3 * n + k] = 2.0 * (w[n] * a[k] + cs[n] * r[k])
            Gt[3 * n + k] = -2.0 * (w[n] * b[k] + ct[n] * r[k])
    if s_free and t_free:
        # inverse of f_uu = 2 [[A, -B], [-B, E]]
        Bab = a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
        det = 2.0 * (A * E - Bab * Bab)
        iss, itt, ist = E / det, A / det, Bab / det
        for i in range(12):
            for j in range(12):
                hess[i, j] -= (
                    iss * Gs[i] * Gs[j]
                    + itt * Gt[i] * Gt[j]
                    + ist * (Gs[i] * Gt[j] + Gt[i] * Gs[j])
                )
    elif s_free:
        for i in range(12):
            for j in range(12):
                hess[i, j] -= Gs[i] * Gs[j] / (2.0 * A)
    else:
        for i in range(12):
            for j in range(12):
                hess[i, j] -= Gt[i] * Gt[j] / (2.0 * E)
    return D


@njit(cache=True)
def pair_distances(x, pairs):  # pragma: no cover - compiled
    """Centre-line distances (P,) of segment pairs ``pairs`` (P, 4) of nodes ``x`` (M, 3)."""
    out = np.empty(pairs.shape[0])
    for p in range(pairs.shape[0]):
        out[p] = np.sqrt(pair_distance2(x, pairs[p, 0], pairs[p, 1], pairs[p, 2], pairs[p, 3]))
    return out


@njit(cache=True)
def node_motions(x, x_ref, out):  # pragma: no cover - compiled
    """Distance (mm) each node of ``x`` (N, 3) has moved from ``x_ref`` into ``out[:N]``, with
    ``out[N:]`` = 0 (fixed obstacle points of an extended point array); returns the largest
    (NaN if any is). The same sums as ``np.sqrt(((x - x_ref) ** 2).sum(axis=1))``."""
    worst = 0.0
    for i in range(x.shape[0]):
        d0 = x[i, 0] - x_ref[i, 0]
        d1 = x[i, 1] - x_ref[i, 1]
        d2 = x[i, 2] - x_ref[i, 2]
        m = np.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
        out[i] = m
        if m > worst or m != m:
            worst = m if worst == worst else worst
    for i in range(x.shape[0], out.shape[0]):
        out[i] = 0.0
    return worst


@njit(cache=True)
def box_growth(x0, x1, x_ref):  # pragma: no cover - compiled
    """Per axis (3,), the largest ``|x0 - x_ref|`` or ``|x1 - x_ref|`` over the nodes (mm):
    how far the boxes of a step ``x0 -> x1`` reach beyond the nodes ``x_ref``; NaN on an axis
    where a coordinate is."""
    out = np.zeros(3)
    for i in range(x_ref.shape[0]):
        for k in range(3):
            a = abs(x0[i, k] - x_ref[i, k])
            b = abs(x1[i, k] - x_ref[i, k])
            if a != a or b != b:
                out[k] = np.nan  # (stays: no comparison with it holds)
            elif a > out[k] or b > out[k]:
                out[k] = max(a, b)
    return out


@njit(cache=True)
def box_excess(start, end, x):  # pragma: no cover - compiled
    """Largest amount (mm) by which a coordinate of ``x`` lies outside the interval between
    its values in ``start`` and ``end`` (all (N, 3); negative when every one lies inside,
    -inf when N = 0, NaN when any coordinate is)."""
    worst = -np.inf
    for i in range(x.shape[0]):
        for k in range(3):
            a = start[i, k]
            b = end[i, k]
            c = x[i, k]
            if a != a or b != b or c != c:
                return np.nan
            v = max(min(a, b) - c, c - max(a, b))
            if v > worst:
                worst = v
    return worst


#: relative margin by which :func:`distance_bound` must clear a threshold before a caller skips
#: the exact distance on it (far above the bound's round-off)
BOUND_MARGIN = 1e-9


@njit(cache=True)
def distance_bound(x, i0, i1, j0, j1):  # pragma: no cover - compiled
    """Lower bound on the distance of segments ``x[i0] x[i1]`` and ``x[j0] x[j1]``: the distance
    of their midpoints less their half lengths (every point of a segment lies within half its
    length of its midpoint)."""
    c2 = 0.0
    a2 = 0.0
    b2 = 0.0
    for k in range(3):
        c = 0.5 * (x[i0, k] + x[i1, k] - x[j0, k] - x[j1, k])
        a = x[i1, k] - x[i0, k]
        b = x[j1, k] - x[j0, k]
        c2 += c * c
        a2 += a * a
        b2 += b * b
    return np.sqrt(c2) - 0.5 * (np.sqrt(a2) + np.sqrt(b2))
