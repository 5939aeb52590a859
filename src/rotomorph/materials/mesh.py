"""Triangulated filament cross-sections with a phase label per triangle.

Section coordinates (mm): x1 along the interface normal n (= rod director m1, pointing INTO the
active phase), x2 along t × n (= m2). The active phase of a Janus disk is the circular segment
x1 > d, with the interface chord at x1 = d chosen from the active area fraction.

Meshes conform to the interface: each phase is convex, so each is triangulated on its own by
Delaunay (scipy.spatial) with the chord vertices shared. The outer circle is approximated by a
polygon with vertices on the circle (area error ≈ (2π/n)²/6 for n boundary vertices).
Quadrature: the 3-point edge-midpoint rule, exact for quadratics on each triangle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.spatial import Delaunay

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidParameterError


@dataclass(frozen=True, eq=False)
class SectionMesh:
    """Triangle mesh of a cross-section.

    Parameters
    ----------
    points
        Vertex coordinates ``(P, 2)`` (mm) in the (x1 = n, x2 = t × n) frame.
    triangles
        Vertex indices ``(T, 3)``, counter-clockwise.
    active
        ``(T,)`` booleans: triangle belongs to the active phase.
    """

    points: FloatArray
    triangles: IntArray
    active: BoolArray

    def __post_init__(self) -> None:
        pts = np.asarray(self.points, dtype=float)
        tri = np.asarray(self.triangles, dtype=np.int64)
        act = np.asarray(self.active, dtype=bool).reshape(-1)
        if pts.ndim != 2 or pts.shape[1] != 2 or tri.ndim != 2 or tri.shape[1] != 3:
            raise InvalidParameterError("SectionMesh", "points must be (P, 2), triangles (T, 3)")
        if act.shape != (len(tri),):
            raise InvalidParameterError("SectionMesh.active", "needs one flag per triangle")
        a = pts[tri]
        cross = (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1]) - (
            a[:, 1, 1] - a[:, 0, 1]
        ) * (a[:, 2, 0] - a[:, 0, 0])
        flip = cross < 0.0
        tri = tri.copy()
        tri[flip] = tri[flip][:, [0, 2, 1]]
        object.__setattr__(self, "points", pts)
        object.__setattr__(self, "triangles", tri)
        object.__setattr__(self, "active", act)

    @property
    def areas(self) -> FloatArray:
        """Triangle areas ``(T,)`` (mm²)."""
        a = self.points[self.triangles]
        return 0.5 * (
            (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1])
            - (a[:, 1, 1] - a[:, 0, 1]) * (a[:, 2, 0] - a[:, 0, 0])
        )

    def quadrature(self) -> tuple[FloatArray, FloatArray, BoolArray, IntArray]:
        """Edge-midpoint quadrature: points ``(3T, 2)`` (mm), weights ``(3T,)`` (mm²),
        active flags ``(3T,)`` and owning triangle ``(3T,)``; exact for quadratics.
        Computed once per mesh (a value); copies are handed out."""
        rule = self.__dict__.get("_rule")
        if rule is None:
            a = self.points[self.triangles]
            mids = 0.5 * (a + a[:, [1, 2, 0]])
            w = np.repeat(self.areas / 3.0, 3)
            owner = np.repeat(np.arange(len(self.triangles)), 3)
            rule = (mids.reshape(-1, 2), w, np.repeat(self.active, 3), owner)
            object.__setattr__(self, "_rule", rule)
        return tuple(a.copy() for a in rule)  # type: ignore[return-value]


def interface_offset(radius: float, active_fraction: float) -> float:
    """Position d (mm) of the chord x1 = d so that the segment x1 > d has the given area fraction.

    Segment area R² acos(d/R) - d √(R² - d²) = f π R²; d = 0 for f = 1/2, d = -R for f = 1.
    """
    if not math.isfinite(radius) or radius <= 0.0:
        raise InvalidParameterError("radius", f"must be > 0 mm; got {radius}")
    if not 0.0 < active_fraction <= 1.0:
        raise InvalidParameterError("active_fraction", f"must lie in (0, 1]; got {active_fraction}")
    if active_fraction == 1.0:
        return -radius

    def excess(u: float) -> float:
        return (math.acos(u) - u * math.sqrt(1.0 - u * u)) / math.pi - active_fraction

    return radius * brentq(excess, -1.0, 1.0, xtol=1e-15)


def disk_mesh(radius: float, active_fraction: float = 0.5, n_boundary: int = 96) -> SectionMesh:
    """Conforming triangle mesh of a disk cut by the interface chord.

    Parameters
    ----------
    radius
        Filament radius R (mm).
    active_fraction
        Area fraction of the active segment x1 > d, in (0, 1] (1 = pure active disk).
    n_boundary
        Number of polygon vertices on the circle (≥ 16); the interior spacing is 2πR/n.

    Returns
    -------
    SectionMesh
    """
    if n_boundary < 16:
        raise InvalidParameterError("n_boundary", f"must be >= 16; got {n_boundary}")
    d = interface_offset(radius, active_fraction)
    h = 2.0 * math.pi * radius / n_boundary
    n_rings = max(2, round(radius / h))
    pts = [np.zeros((1, 2))]
    for k in range(1, n_rings):
        rk = radius * k / n_rings
        m = max(6, round(2.0 * math.pi * rk / h))
        th = 2.0 * math.pi * (np.arange(m) + 0.5 * (k % 2)) / m
        pts.append(rk * np.column_stack([np.cos(th), np.sin(th)]))
    interior = np.vstack(pts)
    th = 2.0 * math.pi * np.arange(n_boundary) / n_boundary
    circle = radius * np.column_stack([np.cos(th), np.sin(th)])
    if active_fraction == 1.0:
        allp = np.vstack([interior, circle])
        tri = Delaunay(allp).simplices
        return _clean(allp, tri, np.ones(len(tri), dtype=bool))
    half = math.sqrt(radius * radius - d * d)
    n_chord = max(2, math.ceil(2.0 * half / h))
    chord = np.column_stack([np.full(n_chord + 1, d), np.linspace(-half, half, n_chord + 1)])
    keep_i = np.abs(interior[:, 0] - d) > 0.4 * h
    keep_c = np.abs(circle[:, 0] - d) > 0.4 * h
    interior, circle = interior[keep_i], circle[keep_c]
    allp = np.vstack([chord, interior, circle])
    side = np.concatenate(
        [np.zeros(len(chord)), np.sign(np.concatenate([interior, circle])[:, 0] - d)]
    )
    tris, flags = [], []
    for sgn in (1.0, -1.0):
        idx = np.flatnonzero((side == 0.0) | (side == sgn))
        local = Delaunay(allp[idx]).simplices
        tris.append(idx[local])
        flags.append(np.full(len(local), sgn > 0.0))
    return _clean(allp, np.vstack(tris), np.concatenate(flags))


def rectangle_mesh(
    width: float, layers: tuple[float, ...], active_layer: int = 0, n: int = 8
) -> SectionMesh:
    """Structured mesh of a layered rectangle (e.g. a Timoshenko bilayer).

    Layers are stacked along x1 starting at x1 = 0, each split into ``n`` × ``n`` cells of two
    triangles; x2 spans [-width/2, width/2].

    Parameters
    ----------
    width
        Extent along x2 (mm).
    layers
        Thicknesses of the layers along x1 (mm), bottom first.
    active_layer
        Index of the layer flagged active.
    n
        Cells per layer and direction.
    """
    if width <= 0.0 or not layers or min(layers) <= 0.0:
        raise InvalidParameterError("rectangle_mesh", "width and layer thicknesses must be > 0 mm")
    pts, tris, flags = [], [], []
    offset, base = 0.0, 0
    ys = np.linspace(-0.5 * width, 0.5 * width, n + 1)
    for k, t in enumerate(layers):
        xs = np.linspace(offset, offset + t, n + 1)
        gx, gy = np.meshgrid(xs, ys, indexing="ij")
        pts.append(np.column_stack([gx.ravel(), gy.ravel()]))
        i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
        v0 = base + (i * (n + 1) + j).ravel()
        v1, v2, v3 = v0 + (n + 1), v0 + (n + 2), v0 + 1
        tris.append(np.vstack([np.column_stack([v0, v1, v2]), np.column_stack([v0, v2, v3])]))
        flags.append(np.full(2 * n * n, k == active_layer))
        offset += t
        base += (n + 1) ** 2
    return SectionMesh(np.vstack(pts), np.vstack(tris), np.concatenate(flags))


def _clean(points: FloatArray, tri: IntArray, active: BoolArray) -> SectionMesh:
    """Drop degenerate triangles (collinear chord/boundary vertices) and build the mesh."""
    a = points[tri]
    area = 0.5 * np.abs(
        (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1])
        - (a[:, 1, 1] - a[:, 0, 1]) * (a[:, 2, 0] - a[:, 0, 0])
    )
    good = area > 1e-12 * float(np.max(area))
    return SectionMesh(points, tri[good], active[good])
