"""Standard rod problems with exact answers (for tests, benchmarks and examples).

The free helix: a straight rod of length 30 mm and diameter 0.6 mm (E = 1 MPa, G = E/3) with
uniform natural curvature 0.5/mm and twist 0.3/mm relaxes, free–free, into a helix of radius
``kappa / (kappa^2 + tau^2)`` and pitch ``2 pi tau / (kappa^2 + tau^2)`` (for any stiffness
matrix a free rod reaches its natural strains, ``k = k_bar``).

The Euler column: a straight clamped–free column under an axial dead load ``P`` at its tip
buckles at ``P_cr = pi^2 B / (4 L^2)``; above it the clamped–free elastica has its tip at
``x / L = 2 E(k) / K(k) - 1`` and ``y / L = 2 k / K(k)`` with ``K(k) = (pi / 2) sqrt(P / P_cr)``
(complete elliptic integrals of modulus ``k = sin(a / 2)``, ``a`` the tip rotation; Timoshenko &
Gere, *Theory of Elastic Stability*, 2nd ed., 1961, § 2.7).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq
from scipy.special import ellipe, ellipk

from rotomorph.rod.model import Model


@dataclass(frozen=True)
class HelixCase:
    """Parameters of the free-helix problem (mm, MPa, 1/mm)."""

    length: float = 30.0
    radius: float = 0.3
    young: float = 1.0
    curvature: float = 0.5
    twist: float = 0.3

    @property
    def helix_radius(self) -> float:
        """Exact helix radius (mm)."""
        return self.curvature / (self.curvature**2 + self.twist**2)

    @property
    def helix_pitch(self) -> float:
        """Exact helix pitch (mm)."""
        return 2 * np.pi * self.twist / (self.curvature**2 + self.twist**2)

    def model(self, n_nodes: int, anisotropy: float = 1.0) -> Model:
        """The straight rod of ``n_nodes`` nodes with the natural field set.

        ``anisotropy`` multiplies ``B2`` (the free shape must not depend on it).
        """
        inertia = np.pi * self.radius**4 / 4
        s = np.linspace(0.0, self.length, n_nodes)
        model = Model.chain(
            np.c_[s, np.zeros(n_nodes), np.zeros(n_nodes)],
            bending_stiffness1=self.young * inertia,
            bending_stiffness2=anisotropy * self.young * inertia,
            twist_stiffness=self.young / 3 * 2 * inertia,
            axial_stiffness=self.young * np.pi * self.radius**2,
        )
        return model.with_natural(
            curvature1=np.full(n_nodes - 2, self.curvature),
            curvature2=np.zeros(n_nodes - 2),
            twist=np.full(n_nodes - 2, self.twist),
        )


@dataclass(frozen=True)
class EulerColumnCase:
    """Parameters of the clamped–free Euler column (mm, MPa).

    Solve it with its first edge clamped (``Supports.clamp_ends(n)``) and the force
    ``(-ratio * euler_load, 0, 0)`` N on the last node. The clamped first edge is centred on the
    origin, so the free length from the clamp (the midpoint of that edge, where the first
    bending stencil's Voronoi cell starts) to the loaded tip is exactly ``length``; a clamp at a
    node would shift the effective length by half an edge (an error of first order in h).
    """

    length: float = 10.0
    radius: float = 0.3
    young: float = 1.0
    poisson: float = 0.3
    axial_factor: float = 100.0  # EA times this: nearly inextensible

    @property
    def bending_stiffness(self) -> float:
        """B = E pi r^4 / 4 (N mm²)."""
        return self.young * np.pi * self.radius**4 / 4

    @property
    def euler_load(self) -> float:
        """Critical load pi^2 B / (4 L^2) of the clamped–free column (N)."""
        return float(np.pi**2 * self.bending_stiffness / (4 * self.length**2))

    def model(self, n_nodes: int) -> Model:
        """The straight isotropic column of ``n_nodes`` nodes along +x."""
        h = self.length / (n_nodes - 1.5)
        s = -h / 2 + h * np.arange(n_nodes)
        b = self.bending_stiffness
        return Model.chain(
            np.c_[s, 0 * s, 0 * s],
            bending_stiffness1=b,
            bending_stiffness2=b,
            twist_stiffness=b / (1 + self.poisson),
            axial_stiffness=self.axial_factor * self.young * np.pi * self.radius**2,
        )

    @staticmethod
    def elastica_tip(ratio: float) -> tuple[float, float]:
        """Exact tip ``(x / L, lateral / L)`` at ``ratio = P / P_cr > 1`` (module docstring)."""
        big_k = np.sqrt(ratio) * np.pi / 2
        m = brentq(lambda m: ellipk(m) - big_k, 1e-12, 1 - 1e-14)
        return float(2 * ellipe(m) / big_k - 1), float(2 * np.sqrt(m) / big_k)
