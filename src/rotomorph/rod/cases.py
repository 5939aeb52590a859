"""Standard rod problems with exact answers (for tests, benchmarks and examples).

The free helix: a straight rod of length 30 mm and diameter 0.6 mm (E = 1 MPa, G = E/3) with
uniform natural curvature 0.5/mm and twist 0.3/mm relaxes, free–free, into a helix of radius
``kappa / (kappa^2 + tau^2)`` and pitch ``2 pi tau / (kappa^2 + tau^2)`` (for any stiffness
matrix: a free rod reaches ``k = k_bar``; physics notes §1.6).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

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
