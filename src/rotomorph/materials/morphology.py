r"""Closed-form shapes of free filaments with uniform natural curvature and twist.

A free rod (no loads, contact or gravity) reaches zero energy k = k̄ for any stiffness. Uniform
k̄ = (K, 0, τ) with m1 along the curvature direction gives a helix (Kirchhoff's
kinetic analogy, e.g. Love, *A Treatise on the Mathematical Theory of Elasticity*, §270):

* radius ρ = K/(K² + τ²), pitch P = 2πτ/(K² + τ²) (τ > 0: right-handed),
* end-to-end length per arc length L/L0 = abs(τ)/√(K² + τ²), times the axial stretch (1 + ε_c)
  (engineering) or exp(ε_c) (Hencky) when the centre line contracts,
* natural curvature and twist are angles per unit *printed* length (material quantities), so an
  axial stretch λ scales the helix uniformly: radius and pitch × λ, curvature and torsion of the
  actuated centre line K/λ and τ/λ (a uniform strain is a similarity),
* morphology parameter Λ = K/abs(τ): Λ ≥ 1 tight coils (L/L0 ≈ 1/Λ), Λ < 1 helices that open into
  nearly straight twisted filaments (L/L0 ≈ 1 − Λ²/2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

from rotomorph.errors import InvalidParameterError

Label = Literal["coil", "helix", "twisted rod", "straight"]

#: Λ = K/abs(τ) at and above which a shape is called a coil (L/L0 ≤ 1/√2).
COIL_THRESHOLD = 1.0
#: Λ below which the curvature is treated as numerical noise (quadrature round-off of a symmetric
#: section): the shape is a twisted rod, L/L0 = stretch to 1e-12.
TWISTED_ROD_THRESHOLD = 1e-6


@dataclass(frozen=True)
class HelixShape:
    """Free-filament helix of uniform curvature K and torsion τ.

    Attributes
    ----------
    curvature, torsion
        K ≥ 0 and τ (1/mm) of the actuated centre line (per actuated arc length).
    radius, pitch
        Helix radius ρ and pitch P (mm); ``inf`` pitch for a straight rod, 0 for a ring.
    end_to_end_ratio
        L/L0 (dimensionless), including the axial stretch.
    morphology_parameter
        Λ = K/abs(τ) (``inf`` when τ = 0).
    label
        ``"coil"`` (Λ ≥ 1), ``"helix"`` (:data:`TWISTED_ROD_THRESHOLD` ≤ Λ < 1),
        ``"twisted rod"`` (K ≈ 0: Λ below that threshold or K < ``tol``, τ ≠ 0) or
        ``"straight"`` (K, |τ| < ``tol``).
    """

    curvature: float
    torsion: float
    radius: float
    pitch: float
    end_to_end_ratio: float
    morphology_parameter: float
    label: Label


def free_helix(
    curvature: float,
    torsion: float,
    axial_strain: float = 0.0,
    *,
    measure: Literal["hencky", "engineering"] = "hencky",
    tol: float = 1e-9,
) -> HelixShape:
    """Shape of a free filament with uniform natural curvature K and twist τ.

    Parameters
    ----------
    curvature
        Natural curvature magnitude K (1/mm of printed length), ≥ 0 (sign is absorbed in the
        frame).
    torsion
        Natural twist τ (1/mm of printed length), signed.
    axial_strain
        Natural centre-line strain ε_c (dimensionless) scaling L/L0.
    measure
        How ``axial_strain`` converts to a stretch: exp(ε_c) or 1 + ε_c.
    tol
        Curvatures and twists below ``tol`` (1/mm) count as zero for the label.

    Returns
    -------
    HelixShape

    Examples
    --------
    K = 0.59 mm⁻¹, τ = 0.1 mm⁻¹ (composite at ω* = 0.06): L/L0 ≈ 0.17, a coil.
    """
    k0 = abs(float(curvature))
    t0 = float(torsion)
    eps = float(axial_strain)
    if not all(math.isfinite(v) for v in (k0, t0, eps)):
        raise InvalidParameterError(
            "free_helix", "curvature, torsion and axial_strain must be finite"
        )
    if measure == "hencky":
        stretch = math.exp(eps)
    elif measure == "engineering":
        stretch = 1.0 + eps
    else:
        raise InvalidParameterError(
            "measure", f"must be 'hencky' or 'engineering'; got {measure!r}"
        )
    if stretch <= 0.0:
        raise InvalidParameterError("axial_strain", f"gives a non-positive stretch {stretch}")
    # angles per printed length over the stretched arc length: a similarity by the stretch
    k, t = k0 / stretch, t0 / stretch
    k2t2 = k * k + t * t
    if k2t2 == 0.0 or (k < tol and abs(t) < tol):
        return HelixShape(k, t, 0.0, math.inf, stretch, 0.0, "straight")
    radius = k / k2t2
    pitch = 2.0 * math.pi * t / k2t2
    ratio = abs(t) / math.sqrt(k2t2) * stretch
    lam = k / abs(t) if t != 0.0 else math.inf
    if k < tol or lam < TWISTED_ROD_THRESHOLD:
        label: Label = "twisted rod"
    elif lam >= COIL_THRESHOLD:
        label = "coil"
    else:
        label = "helix"
    return HelixShape(k, t, radius, pitch, ratio, lam, label)
