r"""Shape descriptors of filaments: lengths, end-to-end ratios, helix fits and morphology.

================  ====================================================================
quantity          definition (unit)
================  ====================================================================
arc length        :math:`\sum_j |x_{j+1} - x_j|` (mm)
end-to-end        :math:`|x_{N-1} - x_0|` (mm); ratio :math:`L/L_0` against a reference
edge ratio        end-to-end ratio of one lattice edge chain (paper Fig. 3, Q13 "strain")
helix             radius ρ, pitch P (mm, axial rise per turn), handedness (+1 right)
morphology        from curvature κ and twist τ (1/mm), :math:`Λ = κ/|τ|`
================  ====================================================================

For a helix of curvature κ and torsion τ: :math:`ρ = κ/(κ^2+τ^2)`,
:math:`P = 2πτ/(κ^2+τ^2)`, :math:`L/L_0 = |τ|/\sqrt{κ^2+τ^2} = 1/\sqrt{1+Λ^2}`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np
from scipy.optimize import least_squares

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis._validate import as_index, as_points
from rotomorph.analysis.curvature import discrete_curvature, discrete_torsion
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import polyline_strains

__all__ = [
    "HelixFit",
    "Morphology",
    "arc_length",
    "classify_morphology",
    "edge_end_to_end_ratios",
    "end_to_end_length",
    "end_to_end_ratio",
    "fit_helix",
    "mean_edge_strain",
    "polyline_morphology",
    "turn_count",
]


def arc_length(points: FloatArray) -> float:
    """Length of a polyline (mm); 0.0 for fewer than two points."""
    pts = as_points(points, "points")
    if len(pts) < 2:
        return 0.0
    return float(np.linalg.norm(np.diff(pts, axis=0), axis=1).sum())


def end_to_end_length(points: FloatArray) -> float:
    """Distance between the first and last vertex (mm); 0.0 for fewer than two points."""
    pts = as_points(points, "points")
    if len(pts) < 2:
        return 0.0
    return float(np.linalg.norm(pts[-1] - pts[0]))


def end_to_end_ratio(points: FloatArray, reference: FloatArray) -> float:
    """End-to-end length of ``points`` over that of ``reference`` (:math:`L/L_0`).

    Parameters
    ----------
    points
        Current vertices ``(N, 3)`` (mm), ``N >= 2``.
    reference
        Reference (printed) vertices ``(M, 3)`` (mm) whose ends are distinct.

    Raises
    ------
    InvalidParameterError
        When the reference's ends coincide (closed reference loop: the ratio is undefined).
    """
    as_points(points, "points", min_count=2)
    as_points(reference, "reference", min_count=2)
    l0 = end_to_end_length(reference)
    if l0 == 0.0:
        raise InvalidParameterError(
            "reference", "its end points coincide; the end-to-end ratio is undefined"
        )
    return end_to_end_length(points) / l0


def edge_end_to_end_ratios(
    positions: FloatArray, reference: FloatArray, edge_chains: Sequence[IntArray]
) -> FloatArray:
    """End-to-end ratio of every lattice edge chain (dimensionless).

    Parameters
    ----------
    positions
        Current node positions ``(N, 3)`` (mm).
    reference
        Reference (printed) node positions ``(N, 3)`` (mm).
    edge_chains
        One node-index array per lattice edge, from its first to its last node (branch node,
        ghost nodes, branch node).

    Returns
    -------
    ndarray
        ``(C,)`` ratios, one per chain; empty for no chains.
    """
    pos = as_points(positions, "positions")
    ref = as_points(reference, "reference")
    if pos.shape != ref.shape:
        raise InvalidParameterError(
            "reference", f"must have the shape of positions {pos.shape}; got {ref.shape}"
        )
    out = np.empty(len(edge_chains))
    for k, chain in enumerate(edge_chains):
        idx = as_index(chain, f"edge_chains[{k}]", len(pos))
        if len(idx) < 2:
            raise InvalidParameterError(f"edge_chains[{k}]", "needs at least two nodes")
        l0 = float(np.linalg.norm(ref[idx[-1]] - ref[idx[0]]))
        if l0 == 0.0:
            raise InvalidParameterError(
                f"edge_chains[{k}]", "its end nodes coincide in the reference"
            )
        out[k] = np.linalg.norm(pos[idx[-1]] - pos[idx[0]]) / l0
    return out


def mean_edge_strain(
    positions: FloatArray, reference: FloatArray, edge_chains: Sequence[IntArray]
) -> float:
    """Mean end-to-end strain of the lattice edges, ``mean(ratio) - 1``.

    Returns 0.0 for no chains.
    """
    ratios = edge_end_to_end_ratios(positions, reference, edge_chains)
    return float(ratios.mean() - 1.0) if len(ratios) else 0.0


# ----------------------------------------------------------------------------- helix fit


@dataclass(frozen=True)
class HelixFit:
    """A helix fitted to a polyline.

    Attributes
    ----------
    radius
        Helix radius ρ (mm).
    pitch
        Axial rise per turn P (mm), non-negative; 0.0 for a planar coil.
    handedness
        ``+1`` right-handed, ``-1`` left-handed, ``0`` planar.
    axis
        Unit axis direction ``(3,)``, pointing from the first toward the last vertex.
    axis_point
        A point on the axis ``(3,)`` (mm), level with the centroid of the vertices.
    turns
        Number of turns about the axis between the first and last vertex (≥ 0).
    rms_residual
        Root-mean-square distance of the vertices from the fitted helix (mm), approximately.
    """

    radius: float
    pitch: float
    handedness: int
    axis: FloatArray
    axis_point: FloatArray
    turns: float
    rms_residual: float

    @property
    def curvature(self) -> float:
        """Curvature :math:`ρ/(ρ^2 + (P/2π)^2)` of the fitted helix (1/mm)."""
        c = self.pitch / (2.0 * np.pi)
        return float(self.radius / (self.radius**2 + c**2))

    @property
    def torsion(self) -> float:
        """Signed torsion :math:`±(P/2π)/(ρ^2 + (P/2π)^2)` (1/mm), positive if right-handed."""
        c = self.pitch / (2.0 * np.pi)
        return float(self.handedness * c / (self.radius**2 + c**2))


def _perpendicular_basis(a: FloatArray, hint: FloatArray) -> tuple[FloatArray, FloatArray]:
    u = hint - (hint @ a) * a
    if np.linalg.norm(u) < 1e-8:
        u = np.eye(3)[int(np.argmin(np.abs(a)))]
        u = u - (u @ a) * a
    u = u / np.linalg.norm(u)
    return u, np.cross(a, u)


def _helix_residuals(params: FloatArray, x: FloatArray, a0, u0, v0) -> FloatArray:
    alpha, beta, cx, cy, r, z0, k = params
    a = a0 + alpha * u0 + beta * v0
    a = a / np.linalg.norm(a)
    u, v = _perpendicular_basis(a, u0)
    px, py, z = x @ u - cx, x @ v - cy, x @ a
    theta = np.unwrap(np.arctan2(py, px))
    return np.concatenate([np.hypot(px, py) - r, z - z0 - k * theta])


def fit_helix(points: FloatArray) -> HelixFit:
    """Fit a circular helix (radius, pitch, handedness, axis) to a polyline.

    The axis is first estimated as the direction along which the unit edge tangents vary
    least (on an exact, uniformly sampled helix every edge makes the same angle with the
    axis), the radius by a circle fit of the vertices projected across that axis, the pitch by
    a line fit of axial height against the unwrapped polar angle; then all seven parameters
    are refined by nonlinear least squares on radial and axial residuals.

    Parameters
    ----------
    points
        Vertices ``(N, 3)`` (mm), ``N >= 5``, ordered along the curve, turning less than half a
        turn per edge about the axis. Reliable from about half a turn on.

    Returns
    -------
    HelixFit
        Exact (to round-off) for exact helices, including planar circles (pitch 0).

    Raises
    ------
    InvalidParameterError
        Fewer than 5 vertices, or collinear vertices (a straight filament has no helix;
        use :func:`polyline_morphology` first).
    """
    pts = as_points(points, "points", min_count=5)
    center = pts.mean(axis=0)
    x = pts - center
    sv = np.linalg.svd(x, compute_uv=False)
    if sv[1] <= 1e-9 * sv[0]:
        raise InvalidParameterError("points", "are collinear; a straight filament has no helix")
    edges = np.diff(pts, axis=0)
    lengths = np.linalg.norm(edges, axis=1)
    if np.any(lengths == 0.0):
        raise InvalidParameterError("points", "contain repeated consecutive vertices")
    t = edges / lengths[:, None]
    _, vecs = np.linalg.eigh(np.cov(t.T))
    a0 = vecs[:, 0]
    if (pts[-1] - pts[0]) @ a0 < 0:
        a0 = -a0
    u0, v0 = _perpendicular_basis(a0, x[0])
    px, py, z = x @ u0, x @ v0, x @ a0
    lhs = np.stack([2.0 * px, 2.0 * py, np.ones_like(px)], axis=1)
    (cx, cy, c), *_ = np.linalg.lstsq(lhs, px * px + py * py, rcond=None)
    r = float(np.sqrt(max(c + cx * cx + cy * cy, 0.0)))
    theta = np.unwrap(np.arctan2(py - cy, px - cx))
    k, z0 = np.polyfit(theta, z, 1)
    scale = float(sv[0])
    p0 = np.array([0.0, 0.0, cx, cy, r, z0, k])
    sol = least_squares(
        _helix_residuals,
        p0,
        args=(x, a0, u0, v0),
        x_scale=np.r_[1, 1, [scale] * 5],
        xtol=1e-14,
        ftol=1e-14,
        gtol=1e-14,
    )
    alpha, beta, cx, cy, r, z0, k = sol.x
    a = a0 + alpha * u0 + beta * v0
    a /= np.linalg.norm(a)
    u, v = _perpendicular_basis(a, u0)
    if (pts[-1] - pts[0]) @ a < 0:
        # keep the axis pointing from start to end (the handedness does not change)
        a, v, cy, z0, k = -a, -v, -cy, -z0, k
    theta = np.unwrap(np.arctan2(x @ v - cy, x @ u - cx))
    pitch = float(2.0 * np.pi * abs(k))
    planar = pitch <= 1e-9 * max(abs(r), scale)
    return HelixFit(
        radius=float(abs(r)),
        pitch=0.0 if planar else pitch,
        handedness=0 if planar else int(np.sign(k)),
        axis=a,
        axis_point=center + cx * u + cy * v,
        turns=float(abs(theta[-1] - theta[0]) / (2.0 * np.pi)),
        rms_residual=float(np.sqrt(np.mean(sol.fun**2))),
    )


def turn_count(points: FloatArray) -> float:
    """Number of coil turns of a filament about its fitted helix axis (see :func:`fit_helix`)."""
    return fit_helix(points).turns


# ----------------------------------------------------------------------------- morphology


class Morphology(str, Enum):
    """Deformation mode of a free filament (paper Fig. 2)."""

    STRAIGHT = "straight"
    TWISTED_ROD = "twisted rod"
    HELIX = "helix"
    COIL = "coil"


def classify_morphology(
    curvature: float,
    twist: float,
    *,
    length: float,
    angle_tolerance: float = 0.1,
    coil_ratio: float = 1.0,
    twisted_ratio: float = 0.05,
) -> Morphology:
    """Label a filament from its curvature and twist, using :math:`Λ = κ/|τ|`.

    Parameters
    ----------
    curvature
        Curvature κ ≥ 0 (1/mm).
    twist
        Twist or torsion τ (1/mm), either sign.
    length
        Arc length (mm), turning the rates into total angles.
    angle_tolerance
        Total bending κL and twist |τ|L below this (rad) count as none.
    coil_ratio
        :math:`Λ \\ge` ``coil_ratio`` is a coil (:math:`L/L_0 \\le 1/\\sqrt{1+Λ^2}`; 0.71 by
        default).
    twisted_ratio
        :math:`Λ <` ``twisted_ratio`` is a twisted rod (nearly straight centre-line).

    Returns
    -------
    Morphology
        ``STRAIGHT`` (no bending, no twist), ``TWISTED_ROD`` (twist only, or Λ tiny), ``HELIX``
        or ``COIL``.
    """
    if not (np.isfinite(curvature) and curvature >= 0):
        raise InvalidParameterError("curvature", f"must be finite and >= 0 1/mm; got {curvature}")
    if not np.isfinite(twist):
        raise InvalidParameterError("twist", f"must be finite (1/mm); got {twist}")
    if not (np.isfinite(length) and length > 0):
        raise InvalidParameterError("length", f"must be > 0 mm; got {length}")
    bent = curvature * length >= angle_tolerance
    twisted = abs(twist) * length >= angle_tolerance
    if not bent:
        return Morphology.TWISTED_ROD if twisted else Morphology.STRAIGHT
    ratio = np.inf if twist == 0 else curvature / abs(twist)
    if ratio >= coil_ratio:
        return Morphology.COIL
    return Morphology.HELIX if ratio >= twisted_ratio else Morphology.TWISTED_ROD


def polyline_morphology(
    points: FloatArray,
    directors: FloatArray | None = None,
    *,
    angle_tolerance: float = 0.1,
    coil_ratio: float = 1.0,
    twisted_ratio: float = 0.05,
) -> Morphology:
    """Label a polyline with :func:`classify_morphology` from its median curvature and twist.

    Parameters
    ----------
    points
        Vertices ``(N, 3)`` (mm), ``N >= 4``.
    directors
        Material directors ``m1`` of the edges ``(N-1, 3)``. With them the twist is the
        material twist (so a straight twisted rod is recognised); without them it is the Frenet
        torsion of the centre-line (0 where undefined).
    angle_tolerance, coil_ratio, twisted_ratio
        Thresholds of :func:`classify_morphology`.
    """
    pts = as_points(points, "points", min_count=4)
    kappa = float(np.median(discrete_curvature(pts)))
    if directors is not None:
        d = np.asarray(directors, dtype=float)
        if d.shape != (len(pts) - 1, 3):
            raise InvalidParameterError(
                "directors", f"must have shape ({len(pts) - 1}, 3); got {d.shape}"
            )
        _, _, tau, voronoi = polyline_strains(pts, d)
        twist = float(np.median(tau / voronoi))
    else:
        torsion = discrete_torsion(pts)
        torsion = torsion[np.isfinite(torsion)]
        twist = float(np.median(torsion)) if len(torsion) else 0.0
    return classify_morphology(
        kappa,
        twist,
        length=arc_length(pts),
        angle_tolerance=angle_tolerance,
        coil_ratio=coil_ratio,
        twisted_ratio=twisted_ratio,
    )
