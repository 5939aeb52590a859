"""Tube surfaces around a network's segments, split into the active and passive halves.

A segment of a printed Janus filament is a cylinder of radius R split by the interface: the
half on the side of the interface normal n (toward the active ink) is active. :func:`tube_mesh`
turns a network's segments into quadrilateral facets (``facets`` around each segment, mitred at
ordinary nodes, where neighbouring segments share their end rings: no gaps, no seams) and tells,
per facet, whether it lies on the active side. With an active area fraction f ≠ ½ the interface
is a chord at distance d from the axis, :math:`f = (θ - \\sin θ)/2π` with
:math:`θ = 2\\arccos(d/R)`; a facet is active when its outward direction u satisfies
:math:`u·n > d/R`.
"""

from __future__ import annotations

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidParameterError

__all__ = ["interface_offset", "quad_corners", "tube_mesh"]


def interface_offset(active_fraction: float) -> float:
    """Distance d/R of the interface chord from the axis for an active area fraction f.

    Solves :math:`f = (θ - \\sin θ)/2π`, :math:`θ = 2\\arccos(d/R)` by bisection; f = ½ → 0,
    f → 0 → 1, f → 1 → −1.
    """
    f = float(active_fraction)
    if not 0.0 <= f <= 1.0:
        raise InvalidParameterError("active_fraction", f"must lie in [0, 1]; got {f}")
    lo, hi = -1.0, 1.0  # d/R; the segment beyond d shrinks as d grows
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        theta = 2.0 * np.arccos(mid)
        if (theta - np.sin(theta)) / (2.0 * np.pi) > f:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _dot(a: FloatArray, b: FloatArray) -> FloatArray:
    return np.einsum("ij,ij->i", a, b)


def _dot3(a: FloatArray, b: FloatArray) -> FloatArray:
    """Dot product over the last axis, broadcasting."""
    return np.sum(a * b, axis=-1)


def _unit(v: FloatArray) -> FloatArray:
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _any_perpendicular(t: FloatArray) -> FloatArray:
    helper = np.where(np.abs(t[:, 2:3]) < 0.9, [[0.0, 0.0, 1.0]], [[1.0, 0.0, 0.0]])
    return _unit(np.cross(t, helper))


def _end_frames(
    pos: FloatArray, edges: IntArray, t: FloatArray, ref: FloatArray, radius: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Plane normal and reference direction of each segment's two end rings ``(E, 2, 3)``.

    At an ordinary node (two segments, no hairpin) both segments' rings lie in the bisector
    plane (a mitre) and, where their reference directions agree (``ref`` within 90°), share
    the mean of the two, so the rings coincide and the tube has no seam; elsewhere each end
    has its segment's own tangent and reference direction. A turn so sharp that the mitre
    would fold the tube onto itself (``radius · tan(θ/2)`` beyond half the shorter segment,
    e.g. a lattice's corner) keeps both segments' own rings as well.
    """
    lengths = np.linalg.norm(pos[edges[:, 1]] - pos[edges[:, 0]], axis=1)
    n = len(pos)
    incident: list[list[int]] = [[] for _ in range(n)]
    for j, (a, b) in enumerate(edges):
        incident[a].append(j)
        incident[b].append(j)
    out = np.repeat(t[:, None, :], 2, axis=1)
    refs = np.repeat(ref[:, None, :], 2, axis=1)
    for node, inc in enumerate(incident):
        if len(inc) != 2:
            continue
        e, f = inc
        # orient both tangents along the walk e -> node -> f
        te = t[e] if edges[e, 1] == node else -t[e]
        tf = t[f] if edges[f, 0] == node else -t[f]
        if float(te @ tf) < -0.5:  # a hairpin: a mitre would be degenerate
            continue
        half_turn = float(np.linalg.norm(np.cross(te, tf))) / (1.0 + float(te @ tf))
        if max(radius[e], radius[f]) * half_turn > 0.5 * min(lengths[e], lengths[f]):
            continue  # the mitred rings would cross inside the bend
        mitre = _unit(te + tf)
        shared = _unit(ref[e] + ref[f]) if float(ref[e] @ ref[f]) > 0.0 else None
        for j in inc:
            end = 0 if edges[j, 0] == node else 1
            out[j, end] = mitre if float(mitre @ t[j]) >= 0 else -mitre
            if shared is not None:
                refs[j, end] = shared
    return out, refs


def tube_mesh(
    positions: FloatArray,
    edges: IntArray,
    radius: float | FloatArray,
    normals: FloatArray | None = None,
    *,
    facets: int = 16,
    active_fraction: float | FloatArray = 0.5,
) -> tuple[FloatArray, FloatArray, BoolArray | None, IntArray]:
    """Quadrilateral facets of tubes around a network's segments.

    Parameters
    ----------
    positions
        Node positions ``(N, 3)`` (mm).
    edges
        Segments ``(E, 2)``.
    radius
        Tube radius (mm), scalar or per segment ``(E,)``.
    normals
        Interface normal toward the active half per segment ``(E, 3)`` (unit; need not be
        exactly perpendicular to the segment), or ``None`` when the sides are unknown.
    facets
        Facets around each segment (>= 3; even numbers split a symmetric section exactly).
    active_fraction
        Active area fraction of the section, scalar or per segment.

    Returns
    -------
    quads
        ``(E·facets, 4, 3)`` facet corners (mm).
    face_normals
        ``(E·facets, 3)`` outward unit normals.
    active
        ``(E·facets,)`` True on the active side (``None`` without ``normals``).
    segment
        ``(E·facets,)`` index of each facet's segment.
    """
    pos = np.asarray(positions, dtype=float)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if int(facets) != facets or facets < 3:
        raise InvalidParameterError("facets", f"must be an integer >= 3; got {facets}")
    k = int(facets)
    m = len(e)
    r = np.broadcast_to(np.asarray(radius, dtype=float), (m,))
    if not np.all(np.isfinite(r) & (r > 0)):
        raise InvalidParameterError("radius", "must be finite and > 0 mm")
    a, b = pos[e[:, 0]], pos[e[:, 1]]
    t = _unit(b - a)
    ref = _any_perpendicular(t) if normals is None else np.asarray(normals, dtype=float)
    if ref.shape != (m, 3):
        raise InvalidParameterError("normals", f"must have shape ({m}, 3); got {ref.shape}")
    ends, refs = _end_frames(pos, e, t, ref, r)
    centres = np.stack([a, b], axis=1)  # (E, 2, 3)
    u = refs - np.einsum("eij,eij->ei", ends, refs)[..., None] * ends
    bad = np.linalg.norm(u, axis=-1) < 1e-9  # normal along the tangent: any perpendicular
    if bad.any():
        fallback = np.repeat(_any_perpendicular(t)[:, None, :], 2, axis=1)
        u = np.where(bad[..., None], fallback, u)
    u = _unit(u)
    # the circle of radius r about the segment's own axis (from the end plane's reference
    # direction, itself in the end plane), carried along the axis into the end plane: at a
    # mitre both neighbours' cylinders meet the plane in one ellipse, point for point
    tt = t[:, None, :]
    u = _unit(u - _dot3(u, tt)[..., None] * tt)
    v = np.cross(np.broadcast_to(tt, u.shape), u)
    phi = 2.0 * np.pi * np.arange(k + 1) / k
    c, s = np.cos(phi), np.sin(phi)
    around = r[:, None, None, None] * (
        c[None, None, :, None] * u[:, :, None, :] + s[None, None, :, None] * v[:, :, None, :]
    )  # (E, 2, k+1, 3)
    lift = _dot3(around, ends[:, :, None, :]) / _dot3(tt, ends)[:, :, None]
    rings = centres[:, :, None, :] + around - lift[..., None] * tt[:, :, None, :]
    # an end ring that shares its angular origin with the neighbour beyond it (a mitre) starts
    # up to 45° away from this segment's own reference direction: number both rings from the
    # point nearest to that direction, so facet i lies within half a facet of angle 2π(i+½)/k
    # from it at both ends (no facet twisted by more than a facet; the Janus sides by index)
    own = _unit(ref - _dot(ref, t)[:, None] * t)
    own = np.where((np.linalg.norm(own, axis=1) < 1e-9)[:, None], _any_perpendicular(t), own)
    for end in (0, 1):
        off = np.arctan2(_dot(np.cross(own, u[:, end]), t), _dot(own, u[:, end]))
        shift = np.rint(off * k / (2.0 * np.pi)).astype(np.int64)
        if shift.any():
            index = (np.arange(k)[None, :] - shift[:, None]) % k
            ring = np.take_along_axis(rings[:, end, :k], index[:, :, None], axis=1)
            rings[:, end] = np.concatenate([ring, ring[:, :1]], axis=1)
    quads = quad_corners(rings)
    segment = np.repeat(np.arange(m), k)
    # shading: each facet's outward direction from where it is drawn (its centre seen from the
    # axis, in the segment's cross-section)
    ts = t[segment]
    out = quads.mean(axis=1) - 0.5 * (a + b)[segment]
    face_normals = _unit(out - np.einsum("ij,ij->i", out, ts)[:, None] * ts)
    active = None
    if normals is not None:
        frac = np.broadcast_to(np.asarray(active_fraction, dtype=float), (m,))
        offsets = {f: interface_offset(f) for f in np.unique(frac)}
        d = np.array([offsets[f] for f in frac])
        mid_phi = 2.0 * np.pi * (np.arange(k) + 0.5) / k
        active = np.tile(np.cos(mid_phi), m) > d[segment]
    return quads, face_normals, active, segment


def quad_corners(rings: FloatArray) -> FloatArray:
    """Facet corners ``(E·k, 4, 3)`` from end rings ``(E, 2, k+1, 3)`` (last = first point)."""
    m, k = rings.shape[0], rings.shape[2] - 1
    return np.stack(
        [rings[:, 0, :-1], rings[:, 0, 1:], rings[:, 1, 1:], rings[:, 1, :-1]], axis=2
    ).reshape(m * k, 4, 3)
