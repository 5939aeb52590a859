r"""Print paths: polylines in mm built from line, arc, sinusoid and polyline segments.

A :class:`Path` is pure geometry, the nozzle-tip trajectory of one filament. Segments are
chained: each starts where the previous one ended, and ``Line``, ``Arc`` and ``Sinusoid`` start
along the current heading. The heading after a segment is: unchanged after a ``Line`` and after a
``Sinusoid`` (its axis, not its end tangent), turned by ``angle`` after an ``Arc``, and the last
edge's direction after a ``Polyline``.

Conventions
-----------
* Heading :math:`\psi` (rad): angle of the edge direction projected on the xy-plane,
  counter-clockwise from lab +x seen from above, unwrapped along the path.
* Signed planar curvature :math:`\kappa` (1/mm): positive for a left (counter-clockwise) turn,
  i.e. the centre of curvature lies on :math:`\hat z \times t`; computed at interior vertices as
  turning angle / Voronoi length, zero at the two ends.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Union

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidDesignError

__all__ = [
    "Arc",
    "Line",
    "Path",
    "Polyline",
    "Segment",
    "Sinusoid",
    "chain_segments",
    "path_defect",
    "tangent_headings",
]


def _positive(field: str, value: float, unit: str) -> None:
    if not np.isfinite(value) or value <= 0:
        raise InvalidDesignError(field, f"must be a finite number > 0 {unit}; got {value!r}")


@dataclass(frozen=True)
class Line:
    """A straight segment of ``length`` (mm) along the current heading."""

    length: float

    def __post_init__(self) -> None:
        _positive("Line.length", self.length, "mm")


@dataclass(frozen=True)
class Arc:
    """A circular arc of ``radius`` (mm) turning by ``angle`` (rad; > 0 counter-clockwise)."""

    radius: float
    angle: float

    def __post_init__(self) -> None:
        _positive("Arc.radius", self.radius, "mm")
        if not np.isfinite(self.angle) or self.angle == 0:
            raise InvalidDesignError(
                "Arc.angle", f"must be finite and non-zero rad; got {self.angle!r}"
            )


@dataclass(frozen=True)
class Sinusoid:
    r"""A sine wave along the current heading: :math:`y = A\sin(2\pi x/\lambda)`.

    Parameters
    ----------
    amplitude
        :math:`A` (mm), > 0; the wave first swings to the left of the heading.
    wavelength
        :math:`\lambda` (mm), > 0.
    periods
        Number of periods (> 0, may be fractional); the segment's chord is ``periods * wavelength``.
    """

    amplitude: float
    wavelength: float
    periods: float = 1.0

    def __post_init__(self) -> None:
        _positive("Sinusoid.amplitude", self.amplitude, "mm")
        _positive("Sinusoid.wavelength", self.wavelength, "mm")
        _positive("Sinusoid.periods", self.periods, "")


@dataclass(frozen=True)
class Polyline:
    """Explicit vertices ``(M, 3)`` in lab coordinates (mm): straight edges between them.

    If it is not the first segment, its first vertex must coincide with the current end.
    With ``resample`` (default) every edge longer than the path's vertex spacing is split into
    equal parts no longer than it, like the other segments (the given vertices stay vertices,
    so corners are kept); without it the vertices are used as given.
    """

    points: FloatArray
    resample: bool = True

    def __post_init__(self) -> None:
        pts = np.array(self.points, dtype=float)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3) or len(pts) < 2:
            raise InvalidDesignError(
                "Polyline.points", f"must be an (M, 3) array with M >= 2 (mm); got {pts.shape}"
            )
        if pts.shape[1] == 2:
            pts = np.column_stack([pts, np.zeros(len(pts))])
        pts.setflags(write=False)
        object.__setattr__(self, "points", pts)


Segment = Union[Line, Arc, Sinusoid, Polyline]  # noqa: UP007 (runtime alias, py3.10)


def _check_points(points: FloatArray, field: str = "Path.points") -> FloatArray:
    pts = np.array(points, dtype=float)
    if pts.ndim == 2 and pts.shape[1] == 2:
        pts = np.column_stack([pts, np.zeros(len(pts))])
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InvalidDesignError(field, f"must have shape (N, 3) in mm; got {pts.shape}")
    if len(pts) < 2:
        raise InvalidDesignError(field, f"needs at least 2 vertices; got {len(pts)} (empty path)")
    bad = ~np.isfinite(pts).all(axis=1)
    if bad.any():
        raise InvalidDesignError(
            field, f"must be finite; vertex {int(np.flatnonzero(bad)[0])} is not"
        )
    defect = path_defect(pts)
    if defect is not None:
        raise InvalidDesignError(field, defect[1])
    return pts


def _at(p: FloatArray) -> str:
    """A vertex's position for messages: ``(x, y, z) mm``."""
    return "(" + ", ".join(f"{float(c):.4g}" for c in p) + ") mm"


#: Largest turn (deg) at one vertex: a sharper one retraces the edge just printed.
MAX_TURN_DEG = 179.0


def path_defect(points: FloatArray) -> tuple[int, str] | None:
    """The first vertex at which a finite ``(N, 3)`` path cannot be printed, and why.

    A repeated vertex (zero-length edge), or a turn sharper than :data:`MAX_TURN_DEG` (the
    nozzle would go back over the filament it has just laid, and the tangent there is
    undefined). ``None`` for a printable path.

    Examples
    --------
    >>> path_defect(np.array([[0.0, 0, 0], [5, 0, 0], [0, 0, 0]]))[1][:56]
    'turns back on itself at vertex 1 (5, 0, 0) mm (a 180 deg'
    """
    pts = np.asarray(points, dtype=float)
    edges = np.diff(pts, axis=0)
    lengths = np.linalg.norm(edges, axis=1)
    scale = max(1.0, float(np.abs(pts).max()))
    rep = lengths <= 1e-9 * scale
    if rep.any():
        i = int(np.flatnonzero(rep)[0])
        return i, (
            f"vertices {i} and {i + 1} {_at(pts[i])} are repeated (zero-length edge); remove one"
        )
    unit = edges / lengths[:, None]
    cos = np.einsum("ij,ij->i", unit[:-1], unit[1:])
    back = np.flatnonzero(cos < np.cos(np.radians(MAX_TURN_DEG)))
    if len(back):
        i = int(back[0]) + 1
        turn = float(np.degrees(np.arccos(np.clip(cos[i - 1], -1.0, 1.0))))
        return i, (
            f"turns back on itself at vertex {i} {_at(pts[i])} (a {turn:.0f} deg turn): a "
            "filament cannot be "
            "printed back over itself; offset the return by at least a filament diameter"
        )
    return None


def _count(length: float, spacing: float) -> int:
    return max(1, int(np.ceil(length / spacing - 1e-9)))


def _discretise(seg: Segment, start: FloatArray, heading: float, spacing: float) -> FloatArray:
    """Vertices of one segment after ``start`` (start excluded), shape ``(M, 3)`` (mm)."""
    c, s = np.cos(heading), np.sin(heading)
    if isinstance(seg, Line):
        u = np.linspace(0.0, seg.length, _count(seg.length, spacing) + 1)[1:]
        return start + np.outer(u, [c, s, 0.0])
    if isinstance(seg, Arc):
        m = _count(seg.radius * abs(seg.angle), spacing)
        phi = np.linspace(0.0, seg.angle, m + 1)[1:]
        sign = np.sign(seg.angle)
        # centre on the left (ccw) or right (cw) of the heading
        left = np.array([-s, c, 0.0])
        centre = start + sign * seg.radius * left
        ang0 = heading - sign * np.pi / 2
        ang = ang0 + phi
        return centre + seg.radius * np.column_stack([np.cos(ang), np.sin(ang), np.zeros_like(ang)])
    if isinstance(seg, Sinusoid):
        chord = seg.periods * seg.wavelength
        k = 2 * np.pi / seg.wavelength
        # sample uniformly in arc length: cumulative arc length on a fine grid, inverted
        xq = np.linspace(0.0, chord, 64 * _count(chord, spacing) + 1)
        ds = np.hypot(1.0, seg.amplitude * k * np.cos(k * xq))
        sq = np.concatenate([[0.0], np.cumsum(0.5 * (ds[1:] + ds[:-1]) * np.diff(xq))])
        x = np.interp(np.linspace(0.0, sq[-1], _count(sq[-1], spacing) + 1)[1:], sq, xq)
        y = seg.amplitude * np.sin(k * x)
        return start + np.outer(x, [c, s, 0.0]) + np.outer(y, [-s, c, 0.0])
    if isinstance(seg, Polyline):
        return _polyline_vertices(np.array(seg.points, dtype=float), seg.resample, spacing)[1:]
    raise InvalidDesignError("segments", f"unknown segment type {type(seg).__name__}")


def _polyline_vertices(pts: FloatArray, resample: bool, spacing: float) -> FloatArray:
    """A polyline's vertices, each edge split into ``_count(length, spacing)`` equal parts."""
    if not resample:
        return pts
    out = [pts[:1]]
    for a, b in itertools.pairwise(pts):
        m = _count(float(np.linalg.norm(b - a)), spacing)
        out.append(a + np.outer(np.arange(1, m + 1) / m, b - a))
    return np.concatenate(out)


@dataclass(frozen=True, eq=False)
class Path:
    """A polyline print path.

    Parameters
    ----------
    points
        Vertices ``(N, 3)`` in mm (``(N, 2)`` is accepted and gets ``z = 0``), ``N >= 2``,
        finite, no repeated consecutive vertices.

    Raises
    ------
    InvalidDesignError
        Empty or one-vertex path, NaN/inf coordinates, repeated points.
    """

    points: FloatArray

    def __post_init__(self) -> None:
        pts = _check_points(self.points)
        pts.setflags(write=False)
        object.__setattr__(self, "points", pts)

    # ----------------------------------------------------------------- constructors
    @classmethod
    def from_segments(
        cls,
        segments: Sequence[Segment],
        *,
        start: Sequence[float] = (0.0, 0.0, 0.0),
        heading: float = 0.0,
        spacing: float = 0.1,
    ) -> Path:
        """Chain ``segments`` from ``start`` (mm) along ``heading`` (rad), ≈ ``spacing`` mm apart.

        See :func:`chain_segments`.
        """
        return cls(chain_segments(segments, start=start, heading=heading, spacing=spacing)[0])

    @classmethod
    def line(cls, start: Sequence[float], end: Sequence[float], spacing: float = 0.1) -> Path:
        """Straight path from ``start`` to ``end`` (mm) with vertices ≈ ``spacing`` mm apart."""
        a, b = np.asarray(start, float), np.asarray(end, float)
        n = _count(float(np.linalg.norm(b - a)), spacing)
        return cls(a + np.outer(np.linspace(0, 1, n + 1), b - a))

    # ----------------------------------------------------------------- geometry
    @property
    def n_vertices(self) -> int:
        """Number of vertices ``N``."""
        return len(self.points)

    @property
    def edge_lengths(self) -> FloatArray:
        """Edge lengths ``(N-1,)`` (mm)."""
        return np.linalg.norm(np.diff(self.points, axis=0), axis=1)

    @property
    def arc_length(self) -> FloatArray:
        """Arc length ``s`` at each vertex ``(N,)`` (mm), ``s[0] = 0``."""
        return np.concatenate([[0.0], np.cumsum(self.edge_lengths)])

    @property
    def length(self) -> float:
        """Total length (mm)."""
        return float(self.edge_lengths.sum())

    @property
    def tangents(self) -> FloatArray:
        """Unit edge tangents ``(N-1, 3)``."""
        e = np.diff(self.points, axis=0)
        return e / np.linalg.norm(e, axis=1)[:, None]

    @property
    def heading(self) -> FloatArray:
        """Unwrapped heading ψ of each edge ``(N-1,)`` (rad), ``ψ[0]`` in ``(-π, π]``."""
        e = np.diff(self.points, axis=0)
        return np.unwrap(np.arctan2(e[:, 1], e[:, 0]))

    @property
    def turning_angle(self) -> FloatArray:
        """Signed planar turning angle at each vertex ``(N,)`` (rad; > 0 left), zero at ends."""
        return np.concatenate([[0.0], np.diff(self.heading), [0.0]])

    @property
    def curvature(self) -> FloatArray:
        """Signed planar curvature κ at each vertex ``(N,)`` (1/mm; > 0 left turn), zero at ends."""
        lengths = self.edge_lengths
        vor = np.concatenate([[lengths[0]], 0.5 * (lengths[:-1] + lengths[1:]), [lengths[-1]]])
        return self.turning_angle / vor

    # ----------------------------------------------------------------- transforms
    def resampled(self, spacing: float) -> Path:
        """The same curve re-sampled by arc length, vertices ≈ ``spacing`` mm apart (ends kept)."""
        _positive("spacing", spacing, "mm")
        s = self.arc_length
        n = _count(float(s[-1]), spacing)
        t = np.linspace(0.0, s[-1], n + 1)
        return Path(np.column_stack([np.interp(t, s, self.points[:, k]) for k in range(3)]))

    def scaled(self, factor: float, origin: Sequence[float] = (0.0, 0.0, 0.0)) -> Path:
        """Scale by ``factor`` (> 0) about ``origin`` (mm)."""
        _positive("factor", factor, "")
        o = np.asarray(origin, float)
        return Path(o + factor * (self.points - o))

    def translated(self, offset: Sequence[float]) -> Path:
        """Translate by ``offset`` (mm, length 3)."""
        return Path(self.points + np.asarray(offset, float).reshape(3))

    def reversed(self) -> Path:
        """The same vertices in reverse order."""
        return Path(self.points[::-1])


def chain_segments(
    segments: Sequence[Segment],
    *,
    start: Sequence[float] = (0.0, 0.0, 0.0),
    heading: float = 0.0,
    spacing: float = 0.1,
) -> tuple[FloatArray, np.ndarray]:
    """Vertices of chained segments and the segment that owns each vertex's outgoing edge.

    Parameters
    ----------
    segments
        ``Line``, ``Arc``, ``Sinusoid``, ``Polyline`` (module docstring for chaining rules).
    start
        First vertex (mm); a leading ``Polyline`` replaces it with its own first point.
    heading
        Initial heading ψ (rad).
    spacing
        Target vertex spacing (mm) for lines, arcs and sinusoids.

    Returns
    -------
    points
        ``(N, 3)`` vertices (mm).
    owner
        ``(N,)`` index of the segment of the edge leaving each vertex (the last vertex gets the
        last segment).

    Raises
    ------
    InvalidDesignError
        No segments, bad ``spacing``/``start``, or a polyline that does not start at the
        current end (``segments[i].points``).
    """
    if len(segments) == 0:
        raise InvalidDesignError("segments", "needs at least one segment (empty path)")
    _positive("spacing", spacing, "mm")
    cur = np.array(start, dtype=float).reshape(3)
    if not np.isfinite(cur).all():
        raise InvalidDesignError("start", "must be finite (mm)")
    pieces = [cur[None, :]]
    owners = []
    head = float(heading)
    for i, seg in enumerate(segments):
        if isinstance(seg, Polyline):
            pts = np.array(seg.points, dtype=float)
            if i == 0:
                pieces = [pts[:1]]
            elif not np.allclose(pts[0], cur, atol=1e-9):
                raise InvalidDesignError(
                    f"segments[{i}].points",
                    f"must start at the current end {cur.tolist()} mm; got {pts[0].tolist()}",
                )
            new = _polyline_vertices(pts, seg.resample, spacing)[1:]
            d = pts[-1] - pts[-2]
            head = float(np.arctan2(d[1], d[0]))
        else:
            new = _discretise(seg, cur, head, spacing)
            if isinstance(seg, Arc):
                head += seg.angle
        pieces.append(new)
        owners.append(np.full(len(new), i))
        cur = new[-1]
    owner = np.concatenate([*owners, [len(segments) - 1]])
    return np.concatenate(pieces), owner


def _segment_tangents(segments: Sequence[Segment], heading: float) -> list[tuple[float, float]]:
    """Heading (rad) of the exact tangent at each segment's start and end, chained as
    :func:`chain_segments` chains them (a sinusoid's tangent swings ``atan(A k)`` off its axis)."""
    out = []
    head = float(heading)
    for seg in segments:
        if isinstance(seg, Line):
            out.append((head, head))
        elif isinstance(seg, Arc):
            out.append((head, head + seg.angle))
            head += seg.angle
        elif isinstance(seg, Sinusoid):
            slope = seg.amplitude * 2 * np.pi / seg.wavelength
            end = np.arctan(slope * np.cos(2 * np.pi * seg.periods))
            out.append((head + float(np.arctan(slope)), head + float(end)))
        else:  # a polyline's edges are straight: its first and last edges' headings
            pts = np.array(seg.points, dtype=float)
            first, last = pts[1] - pts[0], pts[-1] - pts[-2]
            head = float(np.arctan2(last[1], last[0]))
            out.append((float(np.arctan2(first[1], first[0])), head))
    return out


def tangent_headings(
    segments: Sequence[Segment],
    points: FloatArray,
    owner: np.ndarray,
    *,
    heading: float = 0.0,
) -> FloatArray:
    """Heading ψ (rad) of the designed curve's tangent at each vertex ``(N,)``, unwrapped.

    ``points`` and ``owner`` are what :func:`chain_segments` returned for ``segments`` and
    ``heading``. A vertex gets the polygon's vertex heading (the mean of its two edges'
    headings, the edge's own at an end), which is the tangent on a line and inside an arc
    (equal chords), except where an arc ends the path or meets a segment tangentially (a
    line, or an arc): there the edge's heading lags the arc's tangent by half the edge's
    turning angle (the mean by a quarter), ``h / (2 R)`` rad for edges of length ``h`` on
    radius ``R`` — 0.48 deg at 1 mm on 60 mm — and the arc's exact tangent is used. Where the
    tangent jumps (a corner between segments) the mean stays.

    Examples
    --------
    >>> segs = [Line(2.0), Arc(10.0, np.pi / 2)]
    >>> pts, owner = chain_segments(segs, spacing=1.0)
    >>> np.degrees(tangent_headings(segs, pts, owner)[[0, 2, -1]]).round(6) + 0.0
    array([ 0.,  0., 90.])
    >>> np.degrees(Path(pts).heading[-1]).round(2)  # the last chord: 2.8 deg (half its turn) short
    np.float64(87.19)
    """
    pts = np.asarray(points, dtype=float)
    e = np.diff(pts, axis=0)
    edge = np.unwrap(np.arctan2(e[:, 1], e[:, 0]))
    psi = np.concatenate([[edge[0]], 0.5 * (edge[1:] + edge[:-1]), [edge[-1]]])
    ends = _segment_tangents(segments, heading)

    def at(i: int, exact: float) -> None:
        psi[i] += (exact - psi[i] + np.pi) % (2 * np.pi) - np.pi  # same branch as the polygon

    if isinstance(segments[0], Arc):
        at(0, ends[0][0])
    if isinstance(segments[-1], Arc):
        at(len(pts) - 1, ends[-1][1])
    for i in np.flatnonzero(owner[1:-1] != owner[:-2]) + 1:  # vertex i ends a, starts b
        a, b = int(owner[i - 1]), int(owner[i])
        jump = (ends[a][1] - ends[b][0] + np.pi) % (2 * np.pi) - np.pi
        if Arc in (type(segments[a]), type(segments[b])) and abs(jump) < 1e-9:
            at(int(i), ends[b][0])
    return psi
