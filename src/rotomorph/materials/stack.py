r"""The printed stack as one cross-section: N fused Janus layers.

A lattice is printed layer by layer, each layer cured onto the one below (the paper's lattices
have three). Every layer is a Janus filament of radius R, and its centre line lies
``layer_height`` h from the next one's along the stacking direction s (the printed sheet's
normal). The section of an edge is the union of the N layer disks, centres
:math:`c_k = o_k\,s` with :math:`o_k = (k - (N-1)/2)\,h`:

* h = 2R (one diameter): neighbouring disks touch on a line (a point of the section); the
  layers are bonded along it.
* h < 2R: neighbouring disks overlap in a lens, the fused band (width
  :math:`2\sqrt{R^2 - h^2/4}`); the lens is split at its middle between the two layers (each
  keeps the part nearer its own nozzle axis).
* h > 2R: the layers do not touch, which no printed stack does (refused).

Each layer keeps its own Janus split (the interface chord at ``interface_offset`` from its
centre, normal n) and its own director field about its own axis (the kinematic helix
tan φ = ω* r/R with r measured from the layer's centre). The section is meshed conforming to
every interface and fusion chord (each convex piece triangulated on its own, shared chord
vertices identical), so the general quadrature (:mod:`rotomorph.materials.section`: axial
stiffness, the 2 x 2 bending matrix about both axes, natural strain and curvature) and the
Saint-Venant torsion with warping (:mod:`rotomorph.materials.torsion`) apply to the whole
fused stack exactly as to one Janus section. :class:`StackSection` is a
:class:`~rotomorph.materials.janus.FilamentSection` (same interface, same remembered print
states) whose eigenstrain fields are those of its layers.

Coordinates are those of the layers' interface frame (x1 = n, x2 = t × n, as
:mod:`rotomorph.materials.mesh`); ``direction`` is s in that frame, e.g. (0, 1) for a lattice
segment whose interface normal lies in the sheet, (1, 0) where it points along the normal.

For touching layers (h = 2R) this reproduces the bonded composite beam of identical layers
(Gere & Goodno, *Mechanics of Materials*, ch. 6: bending about the in-sheet axis N B + EA Σ
o_k², about the normal N B; natural curvature toward s the stiffness-weighted share of one
layer's) and a torsion constant N C (no shear carried across a line): tested.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field
from functools import cached_property, lru_cache

import numpy as np
from scipy.spatial import Delaunay

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.janus import DEFAULT_RESOLUTION, FilamentSection
from rotomorph.materials.mesh import SectionMesh, interface_offset
from rotomorph.materials.section import AxialSection, axial_section, phase_constant
from rotomorph.materials.torsion import TorsionSection

__all__ = ["StackMesh", "StackSection", "stack_mesh", "stack_section", "touching"]

#: Relative tolerance on h = 2R within which layers count as touching (bonded on a line).
TOUCH_TOL = 1e-9


def touching(radius: float, layer_height: float) -> bool:
    """Whether layers ``layer_height`` apart just touch (h = 2R within :data:`TOUCH_TOL`)."""
    return abs(layer_height - 2.0 * radius) <= TOUCH_TOL * 2.0 * radius


@dataclass(frozen=True, eq=False)
class StackMesh:
    """A meshed stack: the mesh, each triangle's layer and the layers' centres (mm)."""

    mesh: SectionMesh
    layer: IntArray  # (T,)
    centres: FloatArray  # (N, 2)


def _clip(poly: FloatArray, normal: FloatArray, offset: float) -> FloatArray:
    """The convex polygon ``poly`` ``(V, 2)`` cut to the half-plane ``normal·x <= offset``
    (Sutherland–Hodgman)."""
    out = []
    n = len(poly)
    for i in range(n):
        p, q = poly[i], poly[(i + 1) % n]
        dp, dq = normal @ p - offset, normal @ q - offset
        if dp <= 0.0:
            out.append(p)
        if (dp < 0.0 < dq) or (dq < 0.0 < dp):
            out.append(p + (q - p) * (dp / (dp - dq)))
    return np.array(out).reshape(-1, 2)


def _on_segment(points: FloatArray, p: FloatArray, q: FloatArray, tol: float) -> FloatArray:
    """Parameters in (0, 1) of the ``points`` lying on the segment p–q (within ``tol``)."""
    d = q - p
    length2 = float(d @ d)
    if length2 == 0.0:
        return np.zeros(0)
    s = (points - p) @ d / length2
    foot = p + s[:, None] * d
    near = np.linalg.norm(points - foot, axis=1) <= tol
    inside = (s > 1e-9) & (s < 1.0 - 1e-9)
    return np.sort(s[near & inside])


def _piece_mesh(
    poly: FloatArray, corners: FloatArray, spacing: float, tol: float
) -> tuple[FloatArray, IntArray]:
    """Triangulate the convex polygon ``poly``: its edges sampled at about ``spacing``, with
    every point of ``corners`` on an edge kept (shared chords stay conforming), plus interior
    points of a triangular grid at least 0.4 spacing inside."""
    boundary = []
    for i in range(len(poly)):
        p, q = poly[i], poly[(i + 1) % len(poly)]
        breaks = np.concatenate([[0.0], _on_segment(corners, p, q, tol), [1.0]])
        for a, b in itertools.pairwise(breaks):
            length = float(np.linalg.norm(q - p)) * (b - a)
            m = max(1, math.ceil(length / spacing - 1e-9))
            for j in range(m):
                boundary.append(p + (q - p) * (a + (b - a) * j / m))
    pts = np.array(boundary)
    lo, hi = poly.min(axis=0), poly.max(axis=0)
    dy = spacing * math.sqrt(3.0) / 2.0
    rows = np.arange(lo[1], hi[1] + dy, dy)
    grid = []
    for r, y in enumerate(rows):
        xs = np.arange(lo[0] + (0.5 * spacing if r % 2 else 0.0), hi[0] + spacing, spacing)
        grid.append(np.column_stack([xs, np.full_like(xs, y)]))
    inner = np.vstack(grid) if grid else np.zeros((0, 2))
    # signed distance to every edge (inside: all negative for a counter-clockwise polygon)
    keep = np.ones(len(inner), dtype=bool)
    for i in range(len(poly)):
        p, q = poly[i], poly[(i + 1) % len(poly)]
        d = q - p
        nrm = np.array([d[1], -d[0]]) / np.linalg.norm(d)  # outward for counter-clockwise
        keep &= (inner - p) @ nrm < -0.4 * spacing
    allp = np.vstack([pts, inner[keep]])
    tri = Delaunay(allp).simplices
    return allp, tri


def _ccw(poly: FloatArray) -> FloatArray:
    x, y = poly[:, 0], poly[:, 1]
    area = 0.5 * float(np.sum(x * np.roll(y, -1) - np.roll(x, -1) * y))
    return poly if area >= 0 else poly[::-1]


def stack_mesh(
    radius: float,
    layers: int,
    layer_height: float,
    active_fraction: float = 0.5,
    direction: tuple[float, float] = (0.0, 1.0),
    n_boundary: int = DEFAULT_RESOLUTION,
) -> StackMesh:
    """Conforming triangle mesh of a stack of Janus layers (module docstring).

    Parameters
    ----------
    radius
        Layer (filament) radius R (mm).
    layers
        Number of layers N (>= 1).
    layer_height
        Distance h between neighbouring layers' centre lines (mm), at most 2R.
    active_fraction
        Area fraction of each layer's active segment x1 > d, in (0, 1].
    direction
        Stacking direction s in the interface frame (normalised).
    n_boundary
        Polygon vertices per layer circle (>= 16, rounded up to even; the spacing of the mesh
        is 2πR/n).

    Returns
    -------
    StackMesh

    Raises
    ------
    InvalidParameterError
        Layers that do not touch (h > 2R), or bad sizes.
    """
    if int(layers) != layers or layers < 1:
        raise InvalidParameterError("layers", f"must be an integer >= 1; got {layers}")
    if not (np.isfinite(radius) and radius > 0):
        raise InvalidParameterError("radius", f"must be > 0 mm; got {radius}")
    if n_boundary < 16:
        raise InvalidParameterError("n_boundary", f"must be an integer >= 16; got {n_boundary}")
    # an even count: every circle has a vertex at +s and at -s, where touching layers meet
    n_boundary = int(n_boundary) + int(n_boundary) % 2
    n_layers = int(layers)
    if n_layers > 1 and not (
        np.isfinite(layer_height) and 0 < layer_height and (
            layer_height < 2.0 * radius or touching(radius, layer_height))
    ):  # fmt: skip
        raise InvalidParameterError(
            "layer_height",
            f"layers {layer_height} mm apart do not touch (filament diameter "
            f"{2.0 * radius:g} mm): a printed stack needs 0 < layer_height <= 2 x radius",
        )
    s = np.asarray(direction, dtype=float)
    s = s / np.linalg.norm(s)
    d = interface_offset(radius, active_fraction)
    spacing = 2.0 * math.pi * radius / n_boundary
    tol = 1e-9 * radius
    psi = math.atan2(s[1], s[0])  # polygon vertices at psi + 2 pi j / n: one points along s
    ang = psi + 2.0 * math.pi * np.arange(n_boundary) / n_boundary
    circle = radius * np.column_stack([np.cos(ang), np.sin(ang)])
    offsets = (np.arange(n_layers) - 0.5 * (n_layers - 1)) * layer_height
    centres = offsets[:, None] * s[None, :]
    fused = n_layers > 1 and not touching(radius, layer_height)
    pieces: list[tuple[FloatArray, int, bool]] = []
    for k in range(n_layers if fused else 1):  # touching layers: translates of one layer
        centre = centres[k] if fused else np.zeros(2)
        poly = centre + circle
        if fused and k < n_layers - 1:  # split the lens with the next layer at its middle
            poly = _clip(poly, s, float(s @ centres[k]) + 0.5 * layer_height)
        if fused and k > 0:
            poly = _clip(poly, -s, -float(s @ centres[k]) + 0.5 * layer_height)
        if active_fraction == 1.0:
            pieces.append((_ccw(poly), k, True))
            continue
        e1 = np.array([1.0, 0.0])
        level = float(e1 @ centre) + d
        pieces.append((_ccw(_clip(poly, -e1, -level)), k, True))  # x1 >= c1 + d: active
        pieces.append((_ccw(_clip(poly, e1, level)), k, False))
    corners = np.vstack([p for p, _, _ in pieces])
    meshed = [(_piece_mesh(poly, corners, spacing, tol), k, act) for poly, k, act in pieces
              if len(poly) >= 3]  # fmt: skip
    if not fused:  # every layer the same triangles in the same order, moved to its centre
        meshed = [((pts + centres[k], tri), k, act) for k in range(n_layers)
                  for (pts, tri), _, act in meshed]  # fmt: skip
    points: list[FloatArray] = []
    tris: list[IntArray] = []
    layer_of: list[IntArray] = []
    flags: list[np.ndarray] = []
    base = 0
    for (pts, tri), k, is_active in meshed:
        points.append(pts)
        tris.append(tri + base)
        layer_of.append(np.full(len(tri), k))
        flags.append(np.full(len(tri), is_active))
        base += len(pts)
    allp = np.vstack(points)
    # merge the vertices the pieces share (chords, touching points)
    key = np.round(allp / tol).astype(np.int64)
    _, first, inverse = np.unique(key, axis=0, return_index=True, return_inverse=True)
    merged = allp[first]
    tri = inverse.reshape(-1)[np.vstack(tris)]
    lay = np.concatenate(layer_of)
    active = np.concatenate(flags)
    a = merged[tri]
    area = 0.5 * np.abs(
        (a[:, 1, 0] - a[:, 0, 0]) * (a[:, 2, 1] - a[:, 0, 1])
        - (a[:, 1, 1] - a[:, 0, 1]) * (a[:, 2, 0] - a[:, 0, 0])
    )
    good = area > 1e-12 * float(area.max())
    mesh = SectionMesh(merged, tri[good], active[good])
    return StackMesh(mesh, lay[good].astype(np.int64), centres)


@dataclass(frozen=True, eq=False)
class StackSection(FilamentSection):
    """A :class:`~rotomorph.materials.janus.FilamentSection` of a fused stack of layers.

    Build with :func:`stack_section` (cached). ``centres`` ``(Q, 2)``: the centre of the layer
    each quadrature point belongs to (its nozzle axis: the director helix winds about it);
    ``layers``, ``layer_height``, ``direction``: the stack's geometry.
    """

    centres: FloatArray = field(default_factory=lambda: np.zeros((0, 2)))
    layers: int = 1
    layer_height: float = 0.0
    direction: tuple[float, float] = (0.0, 1.0)

    @cached_property
    def _local_points(self) -> FloatArray:
        """Quadrature points relative to their layer's centre ``(Q, 2)`` (mm)."""
        return self.axial.points - self.centres

    @cached_property
    def _radial2(self) -> FloatArray:
        """(r / R)² about each point's layer centre ``(Q,)``."""
        xy = self._local_points
        return np.sum(xy * xy, axis=1) / self.radius**2

    def _local(self) -> FloatArray:
        return self._local_points

    def eigenfields(
        self,
        omega_star: float | FloatArray,
        eps_parallel: float | FloatArray,
        eps_perpendicular: float | FloatArray,
        eps_passive: float | FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """As :meth:`FilamentSection.eigenfields`, each layer's helix about its own axis."""
        w, ep, et, eq = (
            np.atleast_1d(np.asarray(a, dtype=float))[:, None]
            for a in (omega_star, eps_parallel, eps_perpendicular, eps_passive)
        )
        eps_zz, denom = self._axial_eigenstrain(w, ep, et, eq)
        xy, act = self._local(), self.axial.active
        factor = np.where(act, 2.0 * (ep - et) * w / (self.radius * denom), 0.0)
        rot = np.column_stack([-xy[:, 1], xy[:, 0]])  # r e_theta about the layer's axis
        return eps_zz, factor[..., None] * rot

    def _axial_eigenstrain(
        self, w: FloatArray, ep: FloatArray, et: FloatArray, eq: FloatArray
    ) -> tuple[FloatArray, FloatArray]:
        act = self.axial.active
        denom = 1.0 + w * w * self._radial2
        return np.where(act, et + (ep - et) / denom, eq), denom


@dataclass(frozen=True, eq=False)
class FoldedStackSection(StackSection):
    """A stack of touching identical layers solved on one layer's quadrature.

    Layers one diameter apart are translates of one another (meshed as such), and every layer
    carries the same print state, so the natural-strain functionals of the whole section fold
    onto one layer's quadrature points: N times its weights, the whole section's stiffnesses,
    and for the curved bar the layers' shifts as an added second moment (exact where the
    printed curvature is perpendicular to the stacking direction, as a planar path's is; other
    curvatures are solved on ``full``). The same values as ``full`` to round-off (tested), a
    third of the work.
    """

    full_key: tuple = ()

    @cached_property
    def full(self) -> StackSection:
        """The whole (unfolded) section, built on first use (torsion, or a printed curvature
        along the stacking direction)."""
        return _full(*self.full_key)

    @cached_property
    def torsion(self) -> TorsionSection:
        """The whole section's torsion, its twist weights folded onto one layer."""
        t = self.full.torsion
        q1 = len(self.axial.points)
        weights = t.twist_weights.reshape(self.layers, q1, 2).sum(axis=0)
        return TorsionSection(t.torsion_constant, t.warping, weights, self.axial.points,
                              self.axial.active)  # fmt: skip

    def curved_strains(
        self,
        omega_star: float | FloatArray,
        eps_parallel: float | FloatArray,
        eps_perpendicular: float | FloatArray,
        eps_passive: float | FloatArray,
        curvature: FloatArray,
    ) -> tuple[FloatArray, FloatArray]:
        """As :meth:`FilamentSection.curved_strains` (on ``full`` where a printed curvature
        has a component along the stacking direction)."""
        k0 = np.asarray(curvature, dtype=float).reshape(-1, 2)
        s = np.asarray(self.direction)
        along = np.abs(k0 @ s) > 1e-12 * np.maximum(np.linalg.norm(k0, axis=1), 1e-300)
        if np.any(along):
            return self.full.curved_strains(
                omega_star, eps_parallel, eps_perpendicular, eps_passive, curvature
            )
        return super().curved_strains(
            omega_star, eps_parallel, eps_perpendicular, eps_passive, curvature
        )


@lru_cache(maxsize=16)
def _mesh(
    radius: float,
    layers: int,
    layer_height: float,
    active_fraction: float,
    direction: tuple[float, float],
    resolution: int,
) -> tuple[StackMesh, FloatArray]:
    """The stack's mesh and each quadrature point's layer centre, shared by every modulus pair
    (the moduli follow the temperature over a ramp; the geometry does not)."""
    sm = stack_mesh(radius, layers, layer_height, active_fraction, direction, resolution)
    _, _, _, owner = sm.mesh.quadrature()
    centres = sm.centres[sm.layer[owner]]
    centres.setflags(write=False)
    return sm, centres


@lru_cache(maxsize=64)
def _cached(
    radius: float,
    layers: int,
    layer_height: float,
    e_active: float,
    e_passive: float,
    g_active: float,
    g_passive: float,
    active_fraction: float,
    direction: tuple[float, float],
    resolution: int,
) -> StackSection:
    key = (radius, layers, layer_height, e_active, e_passive, g_active, g_passive,
           active_fraction, direction, resolution)  # fmt: skip
    if layers == 1 or not touching(radius, layer_height):
        return _full(*key)
    # touching layers: translates of one layer (stack_mesh), folded onto it: N copies of its
    # quadrature, the bonded beam's stiffnesses (parallel axes, exact for translates)
    one, _ = _mesh(radius, 1, 0.0, active_fraction, direction, resolution)
    axial = axial_section(one.mesh, phase_constant(e_active, e_passive))
    s = np.asarray(direction, dtype=float)
    offsets = (np.arange(layers) - 0.5 * (layers - 1)) * layer_height
    moment = float(np.sum(offsets**2))
    folded = AxialSection(
        layers * axial.axial_stiffness,
        axial.centroid,
        layers * axial.bending_matrix + axial.axial_stiffness * moment * np.outer(s, s),
        axial.points,
        layers * axial.weights,
        axial.active,
        axial.modulus,
        folded_moment=moment / layers * np.outer(s, s),
    )
    zero = np.zeros((len(axial.points), 2))
    zero.setflags(write=False)
    sm, _ = _mesh(radius, layers, layer_height, active_fraction, direction, resolution)
    return FoldedStackSection(
        radius,
        sm.mesh,
        folded,
        (g_active, g_passive),
        centres=zero,
        layers=layers,
        layer_height=layer_height,
        direction=direction,
        full_key=key,
    )


@lru_cache(maxsize=16)
def _full(
    radius: float,
    layers: int,
    layer_height: float,
    e_active: float,
    e_passive: float,
    g_active: float,
    g_passive: float,
    active_fraction: float,
    direction: tuple[float, float],
    resolution: int,
) -> StackSection:
    """The whole (unfolded) stack section."""
    sm, centres = _mesh(radius, layers, layer_height, active_fraction, direction, resolution)
    return StackSection(
        radius,
        sm.mesh,
        axial_section(sm.mesh, phase_constant(e_active, e_passive)),
        (g_active, g_passive),
        centres=centres,
        layers=layers,
        layer_height=layer_height,
        direction=direction,
    )


def stack_section(
    radius: float,
    layers: int,
    layer_height: float,
    e_active: float,
    e_passive: float,
    *,
    poisson_active: float = 0.5,
    poisson_passive: float = 0.5,
    active_fraction: float = 0.5,
    direction: tuple[float, float] = (0.0, 1.0),
    resolution: int = DEFAULT_RESOLUTION,
) -> StackSection:
    """The meshed section of a printed stack (module docstring), cached.

    Parameters as :func:`~rotomorph.materials.janus.filament_section`, plus ``layers`` N,
    ``layer_height`` h (mm, at most 2R) and ``direction``, the stacking direction in the
    layers' interface frame. One layer is a Janus disk (the same values as
    :func:`~rotomorph.materials.janus.filament_section` to mesh accuracy).

    Raises
    ------
    InvalidParameterError
        Non-positive moduli or radius; layers that do not touch.
    """
    for name, value in (("e_active", e_active), ("e_passive", e_passive), ("radius", radius)):
        if not np.isfinite(value) or value <= 0.0:
            raise InvalidParameterError(name, f"must be finite and > 0; got {value}")
    s = np.asarray(direction, dtype=float).reshape(-1)
    if s.shape != (2,) or not np.all(np.isfinite(s)) or np.linalg.norm(s) == 0:
        raise InvalidParameterError("direction", f"must be a non-zero 2-vector; got {direction}")
    s = s / np.linalg.norm(s)
    g_a = e_active / (2.0 * (1.0 + poisson_active))
    g_p = e_passive / (2.0 * (1.0 + poisson_passive))
    return _cached(
        float(radius),
        int(layers),
        float(layer_height) if layers > 1 else 0.0,
        float(e_active),
        float(e_passive),
        float(g_a),
        float(g_p),
        float(active_fraction),
        (round(float(s[0]), 12), round(float(s[1]), 12)),
        int(resolution),
    )
