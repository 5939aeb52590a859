"""Is a heated lattice a surface? The quadratic fit's quality and edges that cross themselves.

The paper reads its dome and saddle lattices (Fig. 4) as surfaces: a quadratic fitted to the
branch nodes, its Gaussian sign and characteristic curvature √|k1 k2|. That reading means
something only where the lattice *is* such a surface: the branch nodes lie close to the fitted
quadratic (its residual small against its rise) and the edges run across it as curves, not
coiled into loops. :func:`surface_quality` measures both:

* ``rise``: the extent of the branch nodes along the fit's normal (mm), and the fit's RMS
  residual along it relative to the rise;
* ``crossing_edges``: lattice edges whose projection onto the fit's plane crosses itself (an
  edge coiled into a loop, or folded over, seen from above the surface).

A lattice is read as a surface when the relative residual is below ``tolerance`` (default
10 %) and no edge crosses itself.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis.curvature import SurfaceFit, fit_quadratic_surface

__all__ = ["SurfaceQuality", "crosses_itself", "surface_quality"]

#: Largest RMS residual of the quadratic fit, relative to the rise, of a lattice read as a
#: surface.
RESIDUAL_TOLERANCE = 0.1


def _proper_crossing(p: FloatArray, q: FloatArray, r: FloatArray, s: FloatArray) -> bool:
    """Whether the 2D segments p–q and r–s cross at a point inside both."""

    def orient(a: FloatArray, b: FloatArray, c: FloatArray) -> float:
        return float((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]))

    d1, d2 = orient(r, s, p), orient(r, s, q)
    d3, d4 = orient(p, q, r), orient(p, q, s)
    return d1 * d2 < 0.0 and d3 * d4 < 0.0


def crosses_itself(points: FloatArray) -> bool:
    """Whether the planar polyline ``points`` ``(M, 2)`` crosses itself (two non-adjacent
    segments intersect at an interior point of both)."""
    pts = np.asarray(points, dtype=float)
    m = len(pts) - 1
    for i in range(m):
        for j in range(i + 2, m):
            if _proper_crossing(pts[i], pts[i + 1], pts[j], pts[j + 1]):
                return True
    return False


@dataclass(frozen=True)
class SurfaceQuality:
    """How well a lattice state reads as a quadratic surface.

    Attributes
    ----------
    fit
        The quadratic fit of the branch nodes.
    rise
        Extent of the branch nodes along the fit's normal (mm).
    residual
        RMS residual of the fit along its normal (mm).
    crossing_edges
        Lattice edges whose projection onto the fit's plane crosses itself.
    tolerance
        Largest ``residual / rise`` of a surface.
    """

    fit: SurfaceFit
    rise: float
    residual: float
    crossing_edges: tuple[int, ...]
    tolerance: float = RESIDUAL_TOLERANCE

    @property
    def relative_residual(self) -> float:
        """``residual / rise`` (inf for a flat lattice with a residual)."""
        if self.rise > 0.0:
            return self.residual / self.rise
        return 0.0 if self.residual == 0.0 else float("inf")

    @property
    def is_surface(self) -> bool:
        """Residual below ``tolerance`` of the rise and no edge crossing itself."""
        return self.relative_residual < self.tolerance and not self.crossing_edges

    def text(self) -> str:
        """One phrase for reports."""
        edges = (
            "no edge crosses itself in projection"
            if not self.crossing_edges
            else f"{len(self.crossing_edges)} edges cross themselves in projection"
        )
        return (
            f"quadratic fit residual {self.residual:.3g} mm = {100 * self.relative_residual:.1f} "
            f"% of the rise {self.rise:.3g} mm; {edges}"
        )


def surface_quality(
    positions: FloatArray,
    branch: IntArray,
    edge_chains: Sequence[IntArray],
    *,
    tolerance: float = RESIDUAL_TOLERANCE,
) -> SurfaceQuality:
    """Quadratic fit of the branch nodes and the edges crossing themselves (module docstring).

    Parameters
    ----------
    positions
        Node positions ``(N, 3)`` (mm).
    branch
        Indices of the branch nodes (at least 6, not on one line).
    edge_chains
        Node indices of every lattice edge, branch node to branch node.
    tolerance
        Largest relative residual of a surface.
    """
    x = np.asarray(positions, dtype=float)
    fit = fit_quadratic_surface(x[np.asarray(branch)], flat_tolerance=1e-6)
    local = (x - fit.center) @ fit.frame.T
    heights = local[np.asarray(branch), 2]
    rise = float(heights.max() - heights.min())
    crossing = tuple(
        e for e, chain in enumerate(edge_chains) if crosses_itself(local[np.asarray(chain), :2])
    )
    return SurfaceQuality(fit, rise, float(fit.rms_residual), crossing, float(tolerance))
