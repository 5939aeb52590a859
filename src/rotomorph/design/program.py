r"""Print programs: what the printer does along ONE filament (path, speed, nozzle angle).

Symbols (paper, "Rotational multimaterial 3D printing"):

===================  =========================================================================
``speed`` v          print (translation) speed at each vertex (mm/s); the move that *leaves*
                     vertex i runs at ``speed[i]`` (the last value repeats the last move's)
``nozzle_angle``     :math:`\alpha_n`, lab angle of the interface normal n toward the active
                     channel, counter-clockwise from +x seen from above (rad), cumulative
                     (unwrapped): this is what the rotary axis commands
``rotation`` ω       :math:`v\,d\alpha_n/ds` (rad/s) at each vertex
``interface_angle``  :math:`\alpha`, the angle of n in the filament cross-section, measured from
                     :math:`d_1` (= :func:`rotomorph.geometry.space_parallel_directors`, i.e.
                     :math:`+\hat z` for a path in the xy-plane) toward :math:`d_2 = t\times d_1`
``ω*``               rotation number :math:`R\omega/v` (paper eq. for ω*: R = filament
                     radius)
===================  =========================================================================

Interface angle convention (derived, with an assumption): the extrudate leaves the nozzle
flowing along :math:`-\hat z` and is laid down along the path tangent t by the rigid rotation
(about :math:`-\hat z\times t`) that takes :math:`-\hat z` to t. The nozzle's in-plane normal
:math:`(\cos\alpha_n, \sin\alpha_n, 0)` is carried along, which gives, for a planar path with
heading ψ,

.. math:: \alpha = \psi - \alpha_n ,

exactly (constant = 0), so a straight path printed with a rotating nozzle has
:math:`d\alpha/ds = -\omega/v` (:math:`|d\alpha/ds| = \omega/v`, paper), and a fixed nozzle on a
curved path still turns the interface by the heading change. ``interface_angle`` is reported per
edge at the edge's midpoint: the rotary axis moves linearly between vertices, so the edge sees
the mean of its two vertex nozzle angles. With this convention n = -d2 (α = -π/2) is the *left*
side of the path (the inner side of a left turn).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, Union

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import FloatArray
from rotomorph.design.path import Path
from rotomorph.errors import InvalidDesignError
from rotomorph.geometry import signed_angle, space_parallel_directors

__all__ = ["PrintProgram", "Profile"]

#: A per-vertex quantity: a scalar, an ``(N,)`` array, or a function of arc length s (mm).
Profile = Union[float, FloatArray, Callable[[FloatArray], FloatArray]]  # noqa: UP007

_ZERO_CURVATURE = 1e-9  # 1/mm: below this a vertex counts as an inflection point


def _per_vertex(name: str, value: Profile, s: FloatArray) -> FloatArray:
    out = value(s) if callable(value) else value
    arr = np.broadcast_to(np.asarray(out, dtype=float), s.shape) if np.ndim(out) == 0 else out
    arr = np.array(arr, dtype=float)
    if arr.shape != s.shape:
        raise InvalidDesignError(
            name,
            f"must be a scalar, a function of s or have one value per vertex {s.shape}; "
            f"got shape {arr.shape}",
        )
    return arr


def _as_points(path: Path | FloatArray) -> FloatArray:
    return path.points if isinstance(path, Path) else Path(path).points


def _interface_normals(points: FloatArray, nozzle_angle_edge: FloatArray) -> FloatArray:
    """Lab-frame interface normals ``(N-1, 3)`` of the extrudate on each edge (module notes)."""
    e = np.diff(points, axis=0)
    return _laid_down(e / np.linalg.norm(e, axis=1)[:, None], nozzle_angle_edge)


def _laid_down(t: FloatArray, nozzle_angle_edge: FloatArray) -> FloatArray:
    """The nozzle's in-plane normal at angle α_n carried onto a filament along ``t``."""
    m = np.column_stack(
        [np.cos(nozzle_angle_edge), np.sin(nozzle_angle_edge), np.zeros_like(nozzle_angle_edge)]
    )
    # rotation taking a = -z to t (Rodrigues); undefined only for t = +z (printing upward)
    a = np.array([0.0, 0.0, -1.0])
    axis = np.cross(a, t)
    sin = np.linalg.norm(axis, axis=1)
    cos = t @ a
    k = np.where(sin[:, None] > 1e-12, axis / np.maximum(sin, 1e-300)[:, None], [1.0, 0.0, 0.0])
    kxm = np.cross(k, m)
    kdm = np.einsum("ij,ij->i", k, m)
    return m * cos[:, None] + kxm * sin[:, None] + k * (kdm * (1 - cos))[:, None]


@compact_display("duration")
@dataclass(frozen=True, eq=False)
class PrintProgram:
    """What the printer does along one filament.

    Parameters
    ----------
    points
        Nozzle-tip vertices ``(N, 3)`` (mm), ``N >= 2``.
    speed
        Print speed per vertex ``(N,)`` (mm/s), > 0 (a scalar broadcasts).
    nozzle_angle
        Lab nozzle angle :math:`\\alpha_n` per vertex ``(N,)`` (rad), cumulative (see module).
    radius
        Filament radius R (mm), > 0; default 0.3 (paper: ~600 µm diameter).
    active_fraction
        Area fraction of the active ink in the cross-section, in [0, 1]; default 0.5.
    active_material, passive_material
        Material names (default ``"lce"``, ``"acrylate"``).
    layer
        Layer index (>= 0).
    step_flips
        True when the program's flips of the active side (interface-angle changes of π/2 or
        more between two vertices) stand for ideal steps (``flip_length = 0``): the natural
        field then takes them as steps at the edge midpoint, with no director helix wound
        by the flip itself (:attr:`director_rotation`). The G-code still turns the nozzle
        over that one edge.
    tangent_heading
        Heading ψ of the designed curve's tangent at each vertex ``(N,)`` (rad, unwrapped),
        where it differs from the polygon's (:func:`~rotomorph.design.path.tangent_headings`:
        at the ends of arcs); ``None`` (default): the polygon's vertex heading, the mean of
        the two edges' (the edge's own at an end). The heading a nozzle that tracks the path
        follows (:meth:`from_interface_angle`), the one a reversed print mirrors the nozzle
        about, and the one :attr:`director_rotation` measures the nozzle's turn against.

    Raises
    ------
    InvalidDesignError
        Shapes, non-finite values, ``speed <= 0`` (with the vertex index), out-of-range scalars.
    """

    points: FloatArray
    speed: FloatArray
    nozzle_angle: FloatArray
    radius: float = 0.3
    active_fraction: float = 0.5
    active_material: str = "lce"
    passive_material: str = "acrylate"
    layer: int = 0
    step_flips: bool = False
    tangent_heading: FloatArray | None = None

    def __post_init__(self) -> None:
        pts = Path(self.points).points.copy()
        n = len(pts)
        arrays = {}
        names = ("speed", "nozzle_angle") + (("tangent_heading",) if self.has_tangents else ())
        for name in names:
            raw = np.asarray(getattr(self, name), dtype=float)
            arr = np.array(np.broadcast_to(raw, (n,)) if raw.ndim == 0 else raw, dtype=float)
            if arr.shape != (n,):
                raise InvalidDesignError(
                    f"PrintProgram.{name}", f"must have one value per vertex ({n}); got {arr.shape}"
                )
            bad = ~np.isfinite(arr)
            if bad.any():
                i = int(np.flatnonzero(bad)[0])
                raise InvalidDesignError(
                    f"PrintProgram.{name}", f"must be finite; got {arr[i]} at vertex {i}"
                )
            arrays[name] = arr
        slow = arrays["speed"] <= 0
        if slow.any():
            i = int(np.flatnonzero(slow)[0])
            raise InvalidDesignError(
                "PrintProgram.speed", f"must be > 0 mm/s; got {arrays['speed'][i]} at vertex {i}"
            )
        if not (np.isfinite(self.radius) and self.radius > 0):
            raise InvalidDesignError("PrintProgram.radius", f"must be > 0 mm; got {self.radius}")
        if not (0.0 <= self.active_fraction <= 1.0):
            raise InvalidDesignError(
                "PrintProgram.active_fraction", f"must lie in [0, 1]; got {self.active_fraction}"
            )
        for name in ("active_material", "passive_material"):
            if not isinstance(getattr(self, name), str) or not getattr(self, name):
                raise InvalidDesignError(f"PrintProgram.{name}", "must be a non-empty name")
        if int(self.layer) != self.layer or self.layer < 0:
            raise InvalidDesignError(
                "PrintProgram.layer", f"must be an integer >= 0; got {self.layer}"
            )
        for name, value in (("points", pts), *arrays.items()):
            value.setflags(write=False)
            object.__setattr__(self, name, value)
        object.__setattr__(self, "radius", float(self.radius))
        object.__setattr__(self, "active_fraction", float(self.active_fraction))
        object.__setattr__(self, "layer", int(self.layer))

    # ----------------------------------------------------------------- derived
    @property
    def has_tangents(self) -> bool:
        """True when the program carries its curve's tangent headings (``tangent_heading``)."""
        return self.tangent_heading is not None

    @property
    def vertex_heading(self) -> FloatArray:
        """Heading ψ of the path's tangent at each vertex ``(N,)`` (rad, unwrapped).

        ``tangent_heading`` if given, else the polygon's: the mean of the two edges' headings,
        the edge's own at the ends.
        """
        if self.tangent_heading is not None:
            return self.tangent_heading
        return _vertex_heading(self.path)

    @property
    def path(self) -> Path:
        """The print path."""
        return Path(self.points)

    @property
    def arc_length(self) -> FloatArray:
        """Arc length at each vertex ``(N,)`` (mm)."""
        return self.path.arc_length

    @property
    def rotation(self) -> FloatArray:
        """Nozzle rotation rate ω = v dα_n/ds per vertex ``(N,)`` (rad/s)."""
        s = self.arc_length
        return self.speed * np.gradient(self.nozzle_angle, s)

    @property
    def director_rotation(self) -> FloatArray:
        """Rotation rate that winds the director helix, per vertex ``(N,)`` (rad/s).

        The nozzle's rotation *relative to the path heading*, v d(α_n − ψ)/ds = −v dα/ds: the
        ink leaves the nozzle turning with it, and the extrudate between the nozzle and the
        deposited filament is twisted only by the part of that turn the filament's own frame
        does not share. The interface is a material surface, so every material line of the
        section winds around the filament at the interface's rate dα/ds, and the shear-aligned
        director follows the material lines (φ = atan ω*). On a straight path this is
        :attr:`rotation`, the paper's ω; a nozzle that only tracks the heading of a
        curved path (the active half kept on one side) winds no helix. With ``step_flips``
        the ideal flips (interface-angle changes of π/2 or more over one edge) have zero
        length and wind none either.

        The heading ψ at a vertex is the mean of its two edges' headings, the tangent of the
        curve through it; an end vertex has only its edge's, which lags the tangent of a
        curved path by half the neighbour's turn. Where the path curves at an end (the
        neighbour's curvature is 1e-9 /mm or more) the first (last) two vertices, whose
        differences include that heading, continue the rate per length of the third (third
        from last) vertex: a fixed nozzle on an arc winds ω* = −R κ at every vertex, a
        tracking one nothing, and straight ends keep their own rates. The nozzle angles (and
        the G-code) are not changed.
        """
        psi = self.vertex_heading
        d_rel = np.diff(self.nozzle_angle - psi)
        # a nozzle that tracks the heading leaves round-off here, not a rotation (exact zeros
        # also let the section remember one print state for all of those vertices)
        d_rel = np.where(np.abs(d_rel) < 1e-12, 0.0, d_rel)
        if self.step_flips:
            d_rel = np.where(np.abs(d_rel) >= 0.5 * np.pi - 1e-9, 0.0, d_rel)
        relative = np.concatenate([[0.0], np.cumsum(d_rel)])
        per_length = np.gradient(relative, self.arc_length)
        if len(per_length) >= 5:  # a third vertex whose differences use bisector headings
            kappa = self.path.curvature
            if abs(kappa[1]) >= _ZERO_CURVATURE:
                per_length[:2] = per_length[2]
            if abs(kappa[-2]) >= _ZERO_CURVATURE:
                per_length[-2:] = per_length[-3]
        return self.speed * per_length

    @property
    def rotation_number(self) -> FloatArray:
        """Dimensionless rotation rate ω* = Rω/v = R dα_n/ds per vertex ``(N,)``."""
        return self.radius * np.gradient(self.nozzle_angle, self.arc_length)

    @property
    def interface_normals(self) -> FloatArray:
        """Unit interface normals toward the active half, per edge ``(N-1, 3)`` (lab frame)."""
        mid = 0.5 * (self.nozzle_angle[1:] + self.nozzle_angle[:-1])
        return _interface_normals(self.points, mid)

    @property
    def vertex_interface_normals(self) -> FloatArray:
        """Interface normals at the vertices ``(N, 3)`` (lab frame, unit).

        The vertex nozzle angle carried onto the vertex tangent (bisector of the two edges;
        the edge's own at the ends; turned in plane to ``tangent_heading`` where given),
        projected perpendicular to it. The natural field samples
        the active side here (midpoint rule on each vertex's Voronoi cell): a flip between
        two vertices then acts as a step at the edge midpoint, the ideal sharp flip, whatever
        the vertex spacing (:func:`rotomorph.materials.natural.natural_field`).
        """
        e = np.diff(self.points, axis=0)
        te = e / np.linalg.norm(e, axis=1)[:, None]
        t = np.concatenate([te[:1], te[:-1] + te[1:], te[-1:]])
        t /= np.linalg.norm(t, axis=1)[:, None]
        if self.tangent_heading is not None:  # the curve's tangent where the polygon's lags it
            flat = np.hypot(t[:, 0], t[:, 1])
            psi = self.tangent_heading
            t = np.column_stack([flat * np.cos(psi), flat * np.sin(psi), t[:, 2]])
        n = _laid_down(t, self.nozzle_angle)
        n -= np.sum(n * t, axis=1)[:, None] * t
        return n / np.linalg.norm(n, axis=1)[:, None]

    @property
    def interface_angle(self) -> FloatArray:
        """Interface angle α per edge ``(N-1,)`` (rad), from d1 toward d2 = t × d1 (module).

        Unwrapped along the filament; for a planar path exactly ``ψ - mean(α_n)`` per edge.
        """
        pts = self.points
        t = np.diff(pts, axis=0)
        t /= np.linalg.norm(t, axis=1)[:, None]
        d1 = space_parallel_directors(pts)
        alpha = np.unwrap(signed_angle(d1, self.interface_normals, t))
        mid = 0.5 * (self.nozzle_angle[1:] + self.nozzle_angle[:-1])
        ref = self.path.heading[0] - mid[0]
        return alpha + 2 * np.pi * np.round((ref - alpha[0]) / (2 * np.pi))

    @property
    def duration(self) -> float:
        """Print time along the path (s), each edge at the speed of its start vertex."""
        return float(np.sum(self.path.edge_lengths / self.speed[:-1]))

    def with_layer(self, layer: int, z: float | None = None) -> PrintProgram:
        """The same program on ``layer``, optionally moved to height ``z`` (mm)."""
        pts = self.points.copy()
        if z is not None:
            pts[:, 2] = z
        return dataclasses.replace(self, points=pts, layer=layer)

    def translated(self, offset: FloatArray | tuple[float, float, float]) -> PrintProgram:
        """The same program moved by ``offset`` (mm, length 3); angles are unchanged."""
        pts = self.points + np.asarray(offset, dtype=float).reshape(3)
        return dataclasses.replace(self, points=pts)

    # ----------------------------------------------------------------- constructors
    @classmethod
    def from_rotation(
        cls,
        path: Path | FloatArray,
        speed: Profile,
        rotation: Profile = 0.0,
        *,
        initial_angle: float = 0.0,
        **kwargs: object,
    ) -> PrintProgram:
        """Program with a prescribed nozzle rotation rate ω(s).

        Parameters
        ----------
        path
            :class:`Path` or vertices ``(N, 3)`` (mm).
        speed
            v (mm/s): scalar, ``(N,)`` or a function of arc length s (mm).
        rotation
            ω (rad/s): scalar, ``(N,)`` or a function of s. The nozzle angle is
            :math:`\\alpha_n(s) = \\alpha_n(0) + \\int_0^s \\omega/v\\,ds` (trapezoid rule,
            exact for constant ω/v).
        initial_angle
            :math:`\\alpha_n(0)` (rad).
        **kwargs
            ``radius``, ``active_fraction``, ``active_material``, ``passive_material``, ``layer``.
        """
        pts = _as_points(path)
        s = Path(pts).arc_length
        v = _per_vertex("speed", speed, s)
        w = _per_vertex("rotation", rotation, s)
        if (v <= 0).any():
            i = int(np.flatnonzero(v <= 0)[0])
            raise InvalidDesignError("speed", f"must be > 0 mm/s; got {v[i]} at vertex {i}")
        rate = w / v
        angle = initial_angle + np.concatenate(
            [[0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(s))]
        )
        return cls(pts, v, angle, **kwargs)  # type: ignore[arg-type]

    @classmethod
    def from_interface_angle(
        cls,
        path: Path | FloatArray,
        speed: Profile,
        interface_angle: Profile,
        **kwargs: object,
    ) -> PrintProgram:
        """Program whose filament gets the interface angle α(s) (rad), for a planar path.

        ``interface_angle`` is given per vertex (scalar, ``(N,)`` or a function of s in mm) and
        the nozzle follows :math:`\\alpha_n = \\psi_v - \\alpha` with :math:`\\psi_v` the vertex
        heading: ``tangent_heading`` if given in ``kwargs`` (the designed curve's tangent,
        :func:`~rotomorph.design.path.tangent_headings`), else the mean of the adjacent edges'
        headings. The per-edge :attr:`interface_angle` of the result is then the edge mean of
        the vertex values up to O(h²) in curvature changes.
        """
        pts = _as_points(path)
        p = Path(pts)
        alpha = _per_vertex("interface_angle", interface_angle, p.arc_length)
        v = _per_vertex("speed", speed, p.arc_length)
        given = kwargs.get("tangent_heading")
        psi = _vertex_heading(p) if given is None else np.asarray(given, dtype=float)
        if psi.shape != alpha.shape:
            raise InvalidDesignError(
                "tangent_heading", f"must have one value per vertex {alpha.shape}; got {psi.shape}"
            )
        return cls(pts, v, psi - alpha, **kwargs)  # type: ignore[arg-type]

    @classmethod
    def sinusoid_with_active_side(
        cls,
        path: Path | FloatArray,
        speed: Profile,
        side: Literal["outer", "inner"] = "outer",
        *,
        flip_length: float = 0.0,
        **kwargs: object,
    ) -> PrintProgram:
        """Keep the active half on the in-plane outer (or inner) side of the path's curvature.

        Convention: α = +π/2·sign κ (outer) or −π/2·sign κ (inner) at each vertex, so the nozzle
        tracks the heading and flips by π at inflections; a vertex with zero curvature
        (|κ| < 1e-9 /mm, e.g. a lattice branch node) gets α = 0, splitting the flip over its two
        edges. Works for any planar path (sinusoid, lattice line, arc).

        Parameters
        ----------
        path
            :class:`Path` or vertices ``(N, 3)`` in a horizontal plane (mm).
        speed
            v (mm/s): scalar, ``(N,)`` or a function of s.
        side
            ``"outer"`` (active on the convex side: straightening/expanding) or ``"inner"``
            (curling/contracting) [PAPER].
        flip_length
            Arc length (mm) over which each π flip is spread (0: a step at the inflection);
            choose about ``π v / max_rotation`` to respect the machine's rotation limit.
        """
        alpha = active_side_angle(path, side, flip_length)
        kwargs.setdefault("step_flips", flip_length == 0)
        return cls.from_interface_angle(path, speed, alpha, **kwargs)


def _vertex_heading(path: Path) -> FloatArray:
    h = path.heading
    inner = 0.5 * (h[1:] + h[:-1])
    return np.concatenate([[h[0]], inner, [h[-1]]])


def active_side_angle(
    path: Path | FloatArray, side: str | FloatArray = "outer", flip_length: float = 0.0
) -> FloatArray:
    """Per-vertex interface angle (rad) putting the active half outer/inner (see above).

    ``side`` may also be an ``(N,)`` array of +1 (outer) / -1 (inner) per vertex.
    ``flip_length`` (mm, >= 0) spreads each π flip over that arc length (a moving average of
    the step), so the nozzle turns at about ``π v / flip_length`` rad/s.
    """
    p = path if isinstance(path, Path) else Path(path)
    if isinstance(side, str):
        if side not in ("outer", "inner"):
            raise InvalidDesignError("side", f"must be 'outer' or 'inner'; got {side!r}")
        sgn = np.full(p.n_vertices, 1.0 if side == "outer" else -1.0)
    else:
        sgn = np.asarray(side, dtype=float)
    kappa = p.curvature
    sign = np.where(np.abs(kappa) < _ZERO_CURVATURE, 0.0, np.sign(kappa))
    if len(sign) > 2:  # the end vertices have no turning angle: continue the neighbour's side
        sign[0], sign[-1] = sign[1], sign[-2]
    alpha = sgn * sign * (np.pi / 2)
    if not (np.isfinite(flip_length) and flip_length >= 0):
        raise InvalidDesignError("flip_length", f"must be >= 0 mm; got {flip_length}")
    if flip_length > 0:
        s = p.arc_length
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (alpha[1:] + alpha[:-1]) * np.diff(s))])
        lo = np.clip(s - flip_length / 2, 0.0, s[-1])
        hi = np.clip(s + flip_length / 2, 0.0, s[-1])
        alpha = (np.interp(hi, s, cum) - np.interp(lo, s, cum)) / (hi - lo)
    return alpha
