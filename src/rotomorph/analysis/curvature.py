r"""Curvatures of polylines and of the surface through a lattice's branch nodes.

Polylines use the rod solver's conventions (:mod:`rotomorph.geometry`): the pointwise curvature
at an interior vertex is :math:`|kb|/\ell_V` with :math:`kb` the discrete curvature binormal and
:math:`\ell_V = (|e|+|f|)/2` the Voronoi length (1/mm).

Surfaces (paper Fig. 4C/F): the points are aligned to their best-fit plane
(PCA), :math:`z = a x^2 + b xy + c y^2 + d x + e y + f` is fitted by least squares and the
principal curvatures are the eigenvalues of the shape operator :math:`S = I^{-1} II` of that
graph at the centre :math:`(x, y) = (0, 0)`, with

.. math::

   I = \begin{pmatrix} 1+d^2 & de \\ de & 1+e^2 \end{pmatrix},\qquad
   II = \frac{1}{\sqrt{1+d^2+e^2}} \begin{pmatrix} 2a & b \\ b & 2c \end{pmatrix},

so :math:`K = k_1 k_2 = (4ac - b^2)/(1+d^2+e^2)^2`; the small-slope value :math:`4ac - b^2` is
reported as well. The characteristic curvature is :math:`\sqrt{|k_1 k_2|}` (1/mm).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.linalg import eigh

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis._validate import as_index, as_points
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import curvature_binormal, signed_angle, unit

__all__ = [
    "SurfaceFit",
    "discrete_curvature",
    "discrete_torsion",
    "fit_quadratic_surface",
    "network_relative_curvature_change",
    "relative_curvature_change",
]


# ----------------------------------------------------------------------------- polylines


def discrete_curvature(points: FloatArray) -> FloatArray:
    """Pointwise curvature magnitude at the interior vertices of a polyline (1/mm).

    Parameters
    ----------
    points
        Vertices ``(N, 3)`` in mm; consecutive vertices distinct.

    Returns
    -------
    ndarray
        ``(N-2,)`` values :math:`|kb_i| / \\ell_{V,i}` (1/mm); empty for ``N < 3``. For a circle of
        radius R sampled with turning angle φ this is :math:`2\\tan(φ/2)/(2R\\sin(φ/2))
        \\to 1/R`.
    """
    pts = as_points(points, "points")
    if len(pts) < 3:
        return np.zeros(0)
    e = np.diff(pts, axis=0)
    lengths = np.linalg.norm(e, axis=1)
    if np.any(lengths == 0.0):
        raise InvalidParameterError(
            "points", f"edge {int(np.argmin(lengths))} has zero length; remove repeated points"
        )
    kb = curvature_binormal(e[:-1], e[1:])
    return np.linalg.norm(kb, axis=1) / (0.5 * (lengths[:-1] + lengths[1:]))


def discrete_torsion(points: FloatArray, *, tolerance: float = 1e-9) -> FloatArray:
    """Frenet torsion of a polyline on its interior edges (1/mm).

    The torsion on edge ``i`` (between vertices ``i`` and ``i+1``, ``1 <= i <= N-3``) is the
    signed angle about the edge tangent from the binormal at vertex ``i`` to the binormal at
    vertex ``i+1``, divided by the edge length; positive for a right-handed helix.

    Parameters
    ----------
    points
        Vertices ``(N, 3)`` in mm.
    tolerance
        Binormals with ``|kb|`` below this (dimensionless turning measure) are undefined.

    Returns
    -------
    ndarray
        ``(N-3,)`` torsions (1/mm), NaN where a binormal is undefined (straight stretch);
        empty for ``N < 4``.
    """
    pts = as_points(points, "points")
    if len(pts) < 4:
        return np.zeros(0)
    e = np.diff(pts, axis=0)
    kb = curvature_binormal(e[:-1], e[1:])
    mag = np.linalg.norm(kb, axis=1)
    ok = mag > tolerance
    b = np.where(ok[:, None], kb / np.where(ok, mag, 1.0)[:, None], 0.0)
    t = unit(e[1:-1])
    angle = signed_angle(b[:-1], b[1:], t)
    out = angle / np.linalg.norm(e[1:-1], axis=1)
    out[~(ok[:-1] & ok[1:])] = np.nan
    return out


def relative_curvature_change(
    points: FloatArray, reference: FloatArray, *, floor: float | None = None
) -> FloatArray:
    """Per-vertex relative curvature change :math:`(κ - κ_i)/κ_i` of a polyline (paper Fig. 4).

    Parameters
    ----------
    points
        Current vertices ``(N, 3)`` (mm).
    reference
        Printed (initial) vertices ``(N, 3)`` (mm), giving :math:`κ_i`.
    floor
        Vertices where :math:`κ_i \\le` ``floor`` (1/mm) get NaN (the ratio is undefined at
        inflection points). Default: ``1e-9`` times the largest :math:`κ_i`.

    Returns
    -------
    ndarray
        ``(N,)`` values (dimensionless); the two end vertices are NaN (no curvature there).
    """
    pts = as_points(points, "points")
    ref = as_points(reference, "reference")
    if pts.shape != ref.shape:
        raise InvalidParameterError(
            "reference", f"must have the shape of points {pts.shape}; got {ref.shape}"
        )
    out = np.full(len(pts), np.nan)
    if len(pts) < 3:
        return out
    kappa = discrete_curvature(pts)
    kappa_i = discrete_curvature(ref)
    limit = 1e-9 * float(kappa_i.max(initial=0.0)) if floor is None else float(floor)
    ok = kappa_i > limit
    inner = np.full(len(kappa), np.nan)
    inner[ok] = (kappa[ok] - kappa_i[ok]) / kappa_i[ok]
    out[1:-1] = inner
    return out


def network_relative_curvature_change(
    positions: FloatArray,
    reference: FloatArray,
    edge_chains: Sequence[IntArray],
    *,
    floor: float | None = None,
) -> FloatArray:
    """:func:`relative_curvature_change` along every chain of a network, per node ``(N,)``.

    Parameters
    ----------
    positions, reference
        Current and printed node positions ``(N, 3)`` (mm).
    edge_chains
        Node-index arrays, one per lattice edge (branch node, ghost nodes, branch node).
    floor
        See :func:`relative_curvature_change` (1/mm); the default uses the largest printed
        curvature of the whole network.

    Returns
    -------
    ndarray
        ``(N,)`` values; nodes interior to no chain (branch nodes, chain ends) are NaN; a node
        interior to several chains gets their mean.
    """
    pos = as_points(positions, "positions")
    ref = as_points(reference, "reference")
    if pos.shape != ref.shape:
        raise InvalidParameterError(
            "reference", f"must have the shape of positions {pos.shape}; got {ref.shape}"
        )
    chains = [as_index(c, f"edge_chains[{k}]", len(pos)) for k, c in enumerate(edge_chains)]
    # chains of equal length are stacked and done at once (a lattice: all of them), so the cost
    # is a few array operations, not a Python loop over 20 000 edges
    groups: dict[int, list[IntArray]] = {}
    for c in chains:
        groups.setdefault(len(c), []).append(c)
    stacked = {n: np.stack(cs) for n, cs in groups.items() if n >= 3}
    kappa_ref = {n: _stacked_curvature(ref[idx]) for n, idx in stacked.items()}
    if floor is None:
        kmax = max((float(k.max(initial=0.0)) for k in kappa_ref.values()), default=0.0)
        floor = 1e-9 * kmax
    total = np.zeros(len(pos))
    count = np.zeros(len(pos))
    for n, idx in stacked.items():
        kappa, kappa_i = _stacked_curvature(pos[idx]), kappa_ref[n]
        ok = kappa_i > floor
        values = np.where(ok, (kappa - kappa_i) / np.where(ok, kappa_i, 1.0), 0.0)
        inner = idx[:, 1:-1]
        total += np.bincount(inner[ok], weights=values[ok], minlength=len(pos))
        count += np.bincount(inner[ok], minlength=len(pos))
    out = np.full(len(pos), np.nan)
    has = count > 0
    out[has] = total[has] / count[has]
    return out


def _stacked_curvature(points: FloatArray) -> FloatArray:
    """:func:`discrete_curvature` of ``(C, L, 3)`` stacked polylines, ``(C, L-2)`` (1/mm)."""
    e = np.diff(points, axis=1)
    lengths = np.linalg.norm(e, axis=2)
    if np.any(lengths == 0.0):
        c, i = np.argwhere(lengths == 0.0)[0]
        raise InvalidParameterError(
            "points", f"edge {int(i)} of chain {int(c)} has zero length; remove repeated points"
        )
    c, n = e.shape[0], e.shape[1] - 1
    kb = curvature_binormal(e[:, :-1].reshape(-1, 3), e[:, 1:].reshape(-1, 3)).reshape(c, n, 3)
    return np.linalg.norm(kb, axis=2) / (0.5 * (lengths[:, :-1] + lengths[:, 1:]))


# ----------------------------------------------------------------------------- surfaces


@dataclass(frozen=True)
class SurfaceFit:
    """Quadratic surface fitted through points, with curvatures at its centre.

    Attributes
    ----------
    coefficients
        ``(a, b, c, d, e, f)`` of :math:`z = a x^2 + b xy + c y^2 + d x + e y + f` in the local
        frame (a, b, c in 1/mm; d, e dimensionless; f in mm).
    center
        Centroid of the points ``(3,)`` (mm), the origin of the local frame.
    frame
        ``(3, 3)`` rows: local x, y axes and the unit normal (z) in global coordinates. The
        normal is oriented with a non-negative global z component.
    k1, k2
        Principal curvatures ``k1 >= k2`` (1/mm), positive when the surface bends toward the
        normal (a bowl opening toward +z is positive, a dome rising toward +z negative).
    gaussian_curvature
        :math:`k_1 k_2` (1/mm²), independent of the normal's orientation.
    mean_curvature
        :math:`(k_1 + k_2)/2` (1/mm).
    small_slope_gaussian
        :math:`4ac - b^2` (1/mm²), the small-slope approximation.
    gaussian_sign
        ``+1`` (dome-like), ``-1`` (saddle-like) or ``0`` (flat or cylindrical, within
        ``flat_tolerance``).
    characteristic_curvature
        :math:`\\sqrt{|k_1 k_2|}` (1/mm).
    rms_residual
        Root-mean-square fit residual along the normal (mm).
    """

    coefficients: tuple[float, float, float, float, float, float]
    center: FloatArray
    frame: FloatArray
    k1: float
    k2: float
    gaussian_curvature: float
    mean_curvature: float
    small_slope_gaussian: float
    gaussian_sign: int
    characteristic_curvature: float
    rms_residual: float


def _plane_frame(x: FloatArray) -> FloatArray:
    """Rows: two in-plane axes and the best-fit normal (non-negative z) of centred points."""
    _, _, vt = np.linalg.svd(x, full_matrices=True)
    n = vt[2]
    nz = np.flatnonzero(np.abs(n) > 1e-12)
    # upward normal; for a vertical plane, the first non-zero component positive
    flip = n[2] < 0 if abs(n[2]) > 1e-12 else n[nz[0]] < 0
    if flip:
        n = -n
    u = vt[0]
    v = np.cross(n, u)
    return np.stack([u, v, n])


def fit_quadratic_surface(points: FloatArray, *, flat_tolerance: float = 1e-9) -> SurfaceFit:
    """Fit :math:`z = a x^2 + b xy + c y^2 + d x + e y + f` over the best-fit plane.

    Parameters
    ----------
    points
        At least 6 points ``(M, 3)`` (mm), e.g. the branch nodes of a lattice
        (``positions[network.branch]``), not all on one line in the plane.
    flat_tolerance
        The Gaussian sign is 0 when :math:`|K| D^2 \\le` ``flat_tolerance``, with D the largest
        distance of a point from the centroid (mm); dimensionless.

    Returns
    -------
    SurfaceFit
        Coefficients, frame and curvatures at the centroid.

    Raises
    ------
    InvalidParameterError
        Fewer than 6 points, non-finite values, or points that do not determine a quadratic
        (e.g. all on one line, or on two lines).

    Examples
    --------
    A plane gives ``k1 == k2 == 0`` and ``gaussian_sign == 0``; a sphere of radius R sampled on a
    small patch gives ``k1 ≈ k2 ≈ ±1/R`` and sign ``+1``; a saddle ``z = (x² - y²)/(2R)`` gives
    ``k1 ≈ 1/R``, ``k2 ≈ -1/R`` and sign ``-1``; a cylinder gives sign ``0``.
    """
    pts = as_points(points, "points")
    if len(pts) < 6:
        raise InvalidParameterError(
            "points", f"a quadratic surface fit needs at least 6 points; got {len(pts)}"
        )
    center = pts.mean(axis=0)
    x0 = pts - center
    size = float(np.linalg.norm(x0, axis=1).max())
    if size == 0.0:
        raise InvalidParameterError("points", "all points coincide; nothing to fit")
    frame = _plane_frame(x0)
    local = x0 @ frame.T
    x, y, z = local[:, 0] / size, local[:, 1] / size, local[:, 2] / size
    design = np.stack([x * x, x * y, y * y, x, y, np.ones_like(x)], axis=1)
    sv = np.linalg.svd(design, compute_uv=False)
    if sv[-1] <= 1e-10 * sv[0]:
        raise InvalidParameterError(
            "points",
            "do not determine a quadratic surface (collinear or on two lines); "
            "pass points spread over an area",
        )
    coef, *_ = np.linalg.lstsq(design, z, rcond=None)
    residual = design @ coef - z
    # undo the scaling: z/size = A (x/size)^2 ... -> a = A/size, d = D, f = F*size
    a, b, c = coef[0] / size, coef[1] / size, coef[2] / size
    d, e, f = coef[3], coef[4], coef[5] * size
    g = 1.0 + d * d + e * e
    first = np.array([[1.0 + d * d, d * e], [d * e, 1.0 + e * e]])
    second = np.array([[2.0 * a, b], [b, 2.0 * c]]) / np.sqrt(g)
    # eigenvalues of S = I^-1 II as the symmetric-definite pencil (II, I): well conditioned
    # also at umbilics (k1 = k2), where H +- sqrt(H^2 - K) would lose half the digits
    k2, k1 = eigh(second, first, eigvals_only=True)
    gaussian = float((4.0 * a * c - b * b) / (g * g))
    mean = 0.5 * float(k1 + k2)
    sign = 0 if abs(gaussian) * size * size <= flat_tolerance else int(np.sign(gaussian))
    return SurfaceFit(
        coefficients=(float(a), float(b), float(c), float(d), float(e), float(f)),
        center=center,
        frame=frame,
        k1=float(k1),
        k2=float(k2),
        gaussian_curvature=gaussian,
        mean_curvature=mean,
        small_slope_gaussian=float(4.0 * a * c - b * b),
        gaussian_sign=sign,
        characteristic_curvature=float(np.sqrt(abs(gaussian))),
        rms_residual=float(np.sqrt(np.mean(residual**2)) * size),
    )
