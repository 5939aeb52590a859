r"""Discrete geometry of a target centre line: what natural field makes a free filament take it.

A free filament (no loads, no contact, no gravity) reaches zero elastic energy, so its shape is
exactly the curve whose curvature and twist, measured in the filament's material frame, equal
the natural field. For a Janus filament the natural curvature points toward the active half
(the interface normal :math:`\mathbf n = \mathbf m_1`) and the natural twist is the twist of that
frame. So a target curve :math:`\mathbf r(s)` is reachable exactly when, along it,

* the material director :math:`\mathbf m_1` is its curvature normal (up to sign, which selects
  the active side), and
* the twist of that frame equals the natural twist the print produces.

This module measures both on a sampled curve with the discrete-elastic-rod definitions (Bergou et
al. 2008): the integrated curvature binormal at each interior vertex, expressed in a
parallel-transport (Bishop) frame :math:`\{\mathbf u, \mathbf v, \mathbf t\}` as
:math:`(\kappa_u, \kappa_v)`; the angle :math:`\theta` of the curvature normal in that frame,
unwrapped modulo :math:`\pi` so that the normal never jumps (a sign change of the curvature then
means the active half changes side); and the twist :math:`d\theta/ds` of the frame that follows
the normal (zero twist for planar curves, the torsion for curves with non-vanishing curvature).
Where the curvature vanishes the normal is undefined; :math:`\theta` is interpolated across.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.interpolate import CubicSpline

from rotomorph import geometry
from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidDesignError

__all__ = ["CurveGeometry", "curve_geometry", "resample", "self_intersection"]


def resample(points: FloatArray, spacing: float) -> FloatArray:
    """Resample a curve given by points ``(N, 3)`` (mm) uniformly with about ``spacing`` mm.

    The points are joined by a cubic spline in chord length (so that curvature is not
    concentrated at the given points), then the spline is sampled uniformly in its arc length.

    Raises
    ------
    InvalidDesignError
        Fewer than 3 distinct points, non-finite values, or repeated consecutive points.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3 or len(pts) < 3:
        raise InvalidDesignError("target.points", "needs at least 3 points of 3 coordinates (mm)")
    if not np.all(np.isfinite(pts)):
        raise InvalidDesignError("target.points", "must be finite numbers (mm)")
    seg = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(seg <= 1e-12 * max(1.0, float(np.ptp(pts)))):
        i = int(np.argmax(seg <= 1e-12 * max(1.0, float(np.ptp(pts)))))
        raise InvalidDesignError("target.points", f"points {i} and {i + 1} coincide; remove one")
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if not (np.isfinite(spacing) and spacing > 0):
        raise InvalidDesignError("target.spacing", f"must be > 0 mm; got {spacing}")
    spline = CubicSpline(s, pts, axis=0)
    fine = np.linspace(0.0, s[-1], 20 * len(pts) + 1)
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(spline(fine), axis=0), axis=1))])
    n = max(int(np.ceil(arc[-1] / spacing)) + 1, 3)
    return spline(np.interp(np.linspace(0.0, arc[-1], n), arc, fine))


def self_intersection(points: FloatArray, diameter: float) -> tuple[int, int, float] | None:
    """First pair of non-neighbouring segments closer than ``diameter`` (mm), or ``None``.

    Segments within ``diameter`` of arc length of each other are neighbours and not compared.
    Returns ``(i, j, distance)`` for segments ``i < j``.
    """
    pts = np.asarray(points, dtype=float)
    a, b = pts[:-1], pts[1:]
    seg = np.linalg.norm(b - a, axis=1)
    s_mid = np.concatenate([[0.0], np.cumsum(seg)])[:-1] + 0.5 * seg
    n = len(a)
    for i in range(n):
        far = np.flatnonzero(s_mid[i + 1 :] - s_mid[i] > diameter + seg[i]) + i + 1
        if not len(far):
            continue
        d = _segment_distances(a[i], b[i], a[far], b[far])
        hit = np.flatnonzero(d < diameter)
        if len(hit):
            return i, int(far[hit[0]]), float(d[hit[0]])
    return None


def _segment_distances(
    p0: FloatArray, p1: FloatArray, q0: FloatArray, q1: FloatArray
) -> FloatArray:
    """Distances between segment p0p1 and each segment q0[k]q1[k] (closest points, clamped)."""
    d1 = p1 - p0
    d2 = q1 - q0
    r = p0 - q0
    a = float(d1 @ d1)
    e = np.einsum("ij,ij->i", d2, d2)
    f = np.einsum("ij,ij->i", d2, r)
    c = r @ d1
    b = d2 @ d1
    denom = a * e - b * b
    s = np.where(
        denom > 1e-14, np.clip((b * f - c * e) / np.where(denom > 1e-14, denom, 1), 0, 1), 0.0
    )
    t = (b * s + f) / e
    t = np.clip(t, 0.0, 1.0)
    s = np.clip((b * t - c) / a, 0.0, 1.0)
    diff = (p0 + s[:, None] * d1) - (q0 + t[:, None] * d2)
    return np.linalg.norm(diff, axis=1)


@dataclass(frozen=True)
class CurveGeometry:
    """Material-frame geometry a free Janus filament needs to take a sampled curve.

    Attributes
    ----------
    points
        Curve vertices ``(N, 3)`` (mm).
    arc_length
        Arc length at each vertex ``(N,)`` (mm).
    directors
        Material director ``m1`` per edge ``(N-1, 3)``: the curvature normal, unwrapped so that
        it never jumps by pi (unit, perpendicular to the edge).
    curvature
        Signed pointwise curvature toward ``m1`` at interior vertices ``(N-2,)`` (1/mm): where
        negative, the curve bends away from ``m1`` and the active half must sit on the ``-m1``
        side.
    residual_curvature
        Curvature toward ``m2 = t x m1`` ``(N-2,)`` (1/mm); zero for a smooth curve up to the
        discretisation (reported as part of the shape error).
    twist
        Pointwise twist of the ``m1`` frame at interior vertices ``(N-2,)`` (1/mm).
    voronoi_length
        Voronoi length of each interior vertex ``(N-2,)`` (mm).
    defined
        ``(N-2,)`` True where the curvature is large enough for its normal to be defined.
    """

    points: FloatArray
    arc_length: FloatArray
    directors: FloatArray
    curvature: FloatArray
    residual_curvature: FloatArray
    twist: FloatArray
    voronoi_length: FloatArray
    defined: FloatArray

    @property
    def length(self) -> float:
        """Total arc length (mm)."""
        return float(self.arc_length[-1])


def curve_geometry(points: FloatArray, *, flat_curvature: float = 1e-3) -> CurveGeometry:
    """Curvature, normal-following frame and its twist on a sampled curve (module docstring).

    The returned directors, curvatures and twist are exactly the DER natural field (with
    ``m1`` = ``directors``) for which the sampled curve is a zero-energy state.

    Parameters
    ----------
    points
        Curve vertices ``(N, 3)`` (mm), N >= 3.
    flat_curvature
        Curvature (1/mm) below which the normal direction is taken as undefined and its angle
        interpolated from the neighbours.
    """
    pts = np.asarray(points, dtype=float)
    e = np.diff(pts, axis=0)
    lengths = np.linalg.norm(e, axis=1)
    t = e / lengths[:, None]
    u = geometry.space_parallel_directors(pts)
    ku, kv, _ = geometry.pair_strains(e[:-1], e[1:], u[:-1], u[1:])
    vor = 0.5 * (lengths[:-1] + lengths[1:])
    mag = np.hypot(ku, kv) / vor
    defined = mag > flat_curvature
    raw = np.arctan2(kv, ku)
    theta_v = np.zeros(len(raw))
    prev: float | None = None
    for i in np.flatnonzero(defined):
        ang = float(raw[i])
        if prev is not None:
            ang += np.pi * np.round((prev - ang) / np.pi)
        theta_v[i] = ang
        prev = ang
    if defined.any():
        idx = np.flatnonzero(defined)
        theta_v = np.interp(np.arange(len(raw)), idx, theta_v[idx])
    theta_e = np.empty(len(t))
    # end edges: linear extrapolation, so the end vertices see the same twist rate
    if len(theta_v) > 1:
        theta_e[0] = 1.5 * theta_v[0] - 0.5 * theta_v[1]
        theta_e[-1] = 1.5 * theta_v[-1] - 0.5 * theta_v[-2]
    else:
        theta_e[0] = theta_e[-1] = theta_v[0]
    theta_e[1:-1] = 0.5 * (theta_v[:-1] + theta_v[1:])
    m1 = geometry.rotate_about_tangent(u, t, theta_e)
    k1, k2, tw = geometry.pair_strains(e[:-1], e[1:], m1[:-1], m1[1:])
    return CurveGeometry(
        points=pts,
        arc_length=np.concatenate([[0.0], np.cumsum(lengths)]),
        directors=m1,
        curvature=k1 / vor,
        residual_curvature=k2 / vor,
        twist=tw / vor,
        voronoi_length=vor,
        defined=defined,
    )
