r"""Discrete differential geometry of framed polylines (below every layer).

Pure, vectorised NumPy functions shared by the design, materials and rod layers so that
every layer measures curvature and twist with the *same* conventions as the rod solver.

Conventions (Bergou et al., "Discrete Elastic Rods", SIGGRAPH 2008; Bergou et al., "Discrete
Viscous Threads", SIGGRAPH 2010):

=============  ===============================================================
symbol         meaning
=============  ===============================================================
``e``, ``f``   incoming and outgoing edge vectors at a vertex (mm)
``t``          unit tangent of an edge
``kb``         curvature binormal :math:`2\,e\times f/(|e||f|+e\cdot f)` (dimensionless,
               :math:`|kb| = 2\tan(\varphi/2)`, :math:`\varphi` the turning angle)
``m1, m2``     material directors of an edge (:math:`m_2 = t\times m_1`)
``kappa1``     integrated curvature toward ``m1``: :math:`\tfrac12\,kb\cdot(m_2^e+m_2^f)`
``kappa2``     integrated curvature toward ``m2``: :math:`-\tfrac12\,kb\cdot(m_1^e+m_1^f)`
``tau``        integrated twist: signed angle about ``t^f`` from the parallel transport of
               ``m1^e`` to ``m1^f`` (rad)
=============  ===============================================================

Integrated quantities divided by the Voronoi length :math:`(|e|+|f|)/2` give pointwise
curvature and twist in 1/mm.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph._typing import FloatArray

_PARALLEL_TOL = 1e-14


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("...i,...i->...", a, b)


def unit(v: FloatArray) -> FloatArray:
    """Normalise vectors along the last axis.

    Parameters
    ----------
    v
        Array ``(..., 3)``; no vector may have zero length.
    """
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / n


def parallel_transport(u: FloatArray, t1: FloatArray, t2: FloatArray) -> FloatArray:
    """Transport vectors ``u`` from unit tangent ``t1`` to unit tangent ``t2``.

    The transport is the rotation about ``t1 x t2`` that takes ``t1`` to ``t2`` (identity when
    they are parallel). Undefined for antiparallel tangents.

    Parameters
    ----------
    u, t1, t2
        Arrays ``(..., 3)``; ``t1`` and ``t2`` unit vectors.

    Returns
    -------
    ndarray
        Transported vectors, same shape as ``u``.
    """
    u, t1, t2 = np.broadcast_arrays(u, t1, t2)
    b = np.cross(t1, t2)
    s = np.linalg.norm(b, axis=-1)
    c = _dot(t1, t2)
    out = np.array(u, dtype=float, copy=True)
    mask = s > _PARALLEL_TOL
    if np.any(mask):
        bh = b[mask] / s[mask, None]
        uu, a1, a2 = u[mask], t1[mask], t2[mask]
        n1 = np.cross(a1, bh)
        n2 = np.cross(a2, bh)
        out[mask] = (
            _dot(uu, a1)[:, None] * a2 + _dot(uu, n1)[:, None] * n2 + _dot(uu, bh)[:, None] * bh
        )
    # c is only used to document the branch; antiparallel input is the caller's error
    del c
    return out


def signed_angle(u: FloatArray, v: FloatArray, axis: FloatArray) -> FloatArray:
    """Signed angle (rad) from ``u`` to ``v`` about ``axis`` (right-hand rule).

    ``u`` and ``v`` are assumed perpendicular to the unit vector ``axis``.
    """
    return np.arctan2(_dot(np.cross(u, v), axis), _dot(u, v))


def curvature_binormal(e: FloatArray, f: FloatArray) -> FloatArray:
    """Discrete curvature binormal ``2 e x f / (|e||f| + e.f)`` of consecutive edges (mm)."""
    denom = np.linalg.norm(e, axis=-1) * np.linalg.norm(f, axis=-1) + _dot(e, f)
    return 2.0 * np.cross(e, f) / denom[..., None]


def space_parallel_directors(points: FloatArray, first: FloatArray | None = None) -> FloatArray:
    """Reference directors ``d1`` of a polyline by space-parallel transport from the first edge.

    Parameters
    ----------
    points
        Polyline vertices ``(N, 3)`` (mm), ``N >= 2``.
    first
        Director of the first edge; projected perpendicular to it. By default ``+z`` for an edge
        not along ``z`` (so that a planar path in the xy-plane gets ``d1 = z`` on every edge),
        else ``+x``.

    Returns
    -------
    ndarray
        Unit directors ``(N-1, 3)``, each perpendicular to its edge.
    """
    t = unit(np.diff(np.asarray(points, dtype=float), axis=0))
    if first is None:
        first = np.array([0.0, 0.0, 1.0]) if abs(t[0, 2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    d = np.asarray(first, dtype=float) - _dot(first, t[0]) * t[0]
    out = np.empty_like(t)
    _transport_chain(t, d / np.linalg.norm(d), out)
    return out


@njit(cache=True)
def _transport_chain(t, d0, out):  # pragma: no cover - compiled
    """Sequential parallel transport of ``d0`` along the tangents ``t`` (see above)."""
    # scalars only: array temporaries and row assignment would compile numba's shape-checking
    # and error-formatting machinery (about 15 % of the first-run compile time)
    out[0, 0], out[0, 1], out[0, 2] = d0[0], d0[1], d0[2]
    for i in range(1, t.shape[0]):
        a0, a1, a2 = t[i - 1, 0], t[i - 1, 1], t[i - 1, 2]
        b0, b1, b2 = t[i, 0], t[i, 1], t[i, 2]
        u0, u1, u2 = out[i - 1, 0], out[i - 1, 1], out[i - 1, 2]
        bx = a1 * b2 - a2 * b1
        by = a2 * b0 - a0 * b2
        bz = a0 * b1 - a1 * b0
        s = np.sqrt(bx * bx + by * by + bz * bz)
        if s < _PARALLEL_TOL:
            v0, v1, v2 = u0, u1, u2
        else:
            bx, by, bz = bx / s, by / s, bz / s
            n10, n11, n12 = a1 * bz - a2 * by, a2 * bx - a0 * bz, a0 * by - a1 * bx
            n20, n21, n22 = b1 * bz - b2 * by, b2 * bx - b0 * bz, b0 * by - b1 * bx
            ua = u0 * a0 + u1 * a1 + u2 * a2
            un = u0 * n10 + u1 * n11 + u2 * n12
            ub = u0 * bx + u1 * by + u2 * bz
            v0 = ua * b0 + un * n20 + ub * bx
            v1 = ua * b1 + un * n21 + ub * by
            v2 = ua * b2 + un * n22 + ub * bz
        vb = v0 * b0 + v1 * b1 + v2 * b2
        v0, v1, v2 = v0 - vb * b0, v1 - vb * b1, v2 - vb * b2
        norm = np.sqrt(v0 * v0 + v1 * v1 + v2 * v2)
        out[i, 0], out[i, 1], out[i, 2] = v0 / norm, v1 / norm, v2 / norm


def rotate_about_tangent(d1: FloatArray, t: FloatArray, angle: FloatArray) -> FloatArray:
    """Rotate unit directors ``d1`` (perpendicular to ``t``) by ``angle`` (rad) about ``t``."""
    d2 = np.cross(t, d1)
    a = np.asarray(angle, dtype=float)[..., None]
    return np.cos(a) * d1 + np.sin(a) * d2


def pair_strains(
    e: FloatArray, f: FloatArray, m1e: FloatArray, m1f: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray]:
    """Integrated curvatures and twist of vertex stencils (see module table).

    Parameters
    ----------
    e, f
        Incoming and outgoing edge vectors ``(S, 3)`` (mm).
    m1e, m1f
        Material directors of the two edges ``(S, 3)``, unit and perpendicular to their edge.

    Returns
    -------
    kappa1, kappa2, tau
        Arrays ``(S,)``: integrated curvature toward ``m1`` and ``m2`` and integrated twist.
        The twist is reduced to ``(-pi, pi]``.
    """
    te, tf = unit(e), unit(f)
    m2e, m2f = np.cross(te, m1e), np.cross(tf, m1f)
    kb = curvature_binormal(e, f)
    kappa1 = 0.5 * _dot(kb, m2e + m2f)
    kappa2 = -0.5 * _dot(kb, m1e + m1f)
    tau = signed_angle(parallel_transport(m1e, te, tf), m1f, tf)
    return kappa1, kappa2, tau


def curvature_increment(
    te: FloatArray, tf: FloatArray, m1e: FloatArray, m1f: FloatArray, vector: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Material components of a curvature vector at vertex stencils, as the rod measures them.

    A pointwise curvature ``vector`` K (1/mm, toward the side the rod bends to) at a vertex
    with unit bisector b changes the curvature binormal per unit length by b × K; the rod
    reads the components ``½(b × K)·(m2e + m2f)`` and ``-½(b × K)·(m1e + m1f)`` (the same
    averaged frames as :func:`pair_strains`), so these are the natural-curvature increments
    that make the rod's discrete curvature vector equal K.

    Parameters
    ----------
    te, tf
        Unit tangents of the incoming and outgoing edges ``(S, 3)``.
    m1e, m1f
        Their unit material directors ``(S, 3)``.
    vector
        Curvature vectors ``(S, 3)`` (1/mm).

    Returns
    -------
    dkappa1, dkappa2
        ``(S,)`` increments toward m1 and m2 (1/mm).
    """
    m2e, m2f = np.cross(te, m1e), np.cross(tf, m1f)
    dkb = np.cross(unit(te + tf), vector)
    return 0.5 * _dot(dkb, m2e + m2f), -0.5 * _dot(dkb, m1e + m1f)


def polyline_strains(
    points: FloatArray, directors: FloatArray
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
    """Integrated material curvatures, twist and Voronoi lengths of a framed polyline.

    Parameters
    ----------
    points
        Vertices ``(N, 3)`` (mm).
    directors
        Material directors ``m1`` of the ``N-1`` edges, ``(N-1, 3)``.

    Returns
    -------
    kappa1, kappa2, tau, voronoi
        Arrays ``(N-2,)`` at interior vertices; ``voronoi`` in mm.
    """
    e = np.diff(points, axis=0)
    k1, k2, tw = pair_strains(e[:-1], e[1:], directors[:-1], directors[1:])
    lengths = np.linalg.norm(e, axis=-1)
    return k1, k2, tw, 0.5 * (lengths[:-1] + lengths[1:])


def plane_basis(normal: FloatArray) -> FloatArray:
    """Orthonormal ``(3, 2)`` basis ``(e1, e2)`` of the plane perpendicular to the unit
    ``normal``, right-handed with it (``e2 = normal x e1``)."""
    n = np.asarray(normal, dtype=float)
    a = np.cross(n, [1.0, 0.0, 0.0])
    if np.linalg.norm(a) < 0.5:
        a = np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    return np.stack([a, np.cross(n, a)], axis=1)


def best_rotation(points: FloatArray, target: FloatArray) -> FloatArray:
    """The proper rotation ``R`` (3 x 3) minimising ``sum_i |R p_i - q_i|^2`` for centred
    ``(N, 3)`` point sets ``p`` (``points``) and ``q`` (``target``) with corresponding rows
    (Kabsch, *Acta Cryst.* A32, 922, 1976); apply it as ``p @ R.T``."""
    u, _, vt = np.linalg.svd(np.asarray(points, float).T @ np.asarray(target, float))
    d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    return np.asarray(vt.T @ np.diag([1.0, 1.0, d]) @ u.T)
