"""Boundary conditions and external (dead) loads of a static rod problem."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError

STANDARD_GRAVITY = 9.80665  # m/s²


@dataclass(frozen=True)
class Supports:
    """Fixed degrees of freedom.

    Parameters
    ----------
    clamped_edges
        Edges whose two nodes and twist angle are fixed (a clamp fixes position *and* frame).
    pinned_nodes
        Nodes whose position is fixed (free to rotate).
    fixed_twist_edges
        Edges whose twist angle is fixed.
    """

    clamped_edges: Sequence[int] = ()
    pinned_nodes: Sequence[int] = ()
    fixed_twist_edges: Sequence[int] = ()

    @classmethod
    def clamp_ends(cls, n_nodes: int, start: bool = True, end: bool = False) -> Supports:
        """Clamp the first and/or last edge of a single filament of ``n_nodes`` nodes."""
        edges = ([0] if start else []) + ([n_nodes - 2] if end else [])
        return cls(clamped_edges=tuple(edges))

    @property
    def is_free(self) -> bool:
        """True when nothing is fixed (a free-floating body)."""
        return not (self.clamped_edges or self.pinned_nodes)


@dataclass(frozen=True)
class Gravity:
    """Self-weight of the filaments, lumped to the nodes.

    The mass is what was printed: each edge weighs ``line_weight`` times its printed length
    (the network's edge length), so a filament whose actuation shortens its natural rest
    length (a contracting LCE) keeps its weight, its section thickening as it shortens.

    Parameters
    ----------
    density
        Filament density (g/cm³).
    area
        Cross-section area as printed (mm²); scalar or per edge.
    fluid_density
        Density of the surrounding fluid (g/cm³), for buoyancy (silicone oil ≈ 0.97).
    acceleration
        Gravitational acceleration (m/s²).
    direction
        Unit direction of gravity (default ``-z``).
    """

    density: float
    area: float | FloatArray
    fluid_density: float = 0.0
    acceleration: float = STANDARD_GRAVITY
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)

    def __post_init__(self) -> None:
        for name in ("density", "fluid_density", "acceleration"):
            v = getattr(self, name)
            if not np.isfinite(v) or v < 0:
                raise InvalidParameterError(f"Gravity.{name}", f"must be finite and >= 0; got {v}")
        a = np.asarray(self.area, dtype=float)
        if not np.all(np.isfinite(a)) or np.any(a <= 0):
            raise InvalidParameterError("Gravity.area", "must be finite and > 0 mm²")
        d = np.asarray(self.direction, dtype=float)
        if d.shape != (3,) or not np.isfinite(d).all() or np.linalg.norm(d) == 0:
            raise InvalidParameterError("Gravity.direction", "must be a non-zero 3-vector")

    def line_weight(self, n_edges: int) -> FloatArray:
        """Net weight per unit length of each edge (N/mm), buoyancy subtracted."""
        rho = (self.density - self.fluid_density) * 1e-6  # kg/mm³
        return np.broadcast_to(
            rho * np.asarray(self.area, float) * self.acceleration, (n_edges,)
        ).astype(float)


@dataclass(frozen=True)
class Loads:
    """Dead external loads.

    Parameters
    ----------
    forces
        ``(node, (Fx, Fy, Fz))`` point forces (N).
    moments
        ``(node, (Mx, My, Mz))`` point moments (N mm), applied to the edge that starts at the
        node (the last edge for the last node of a chain).
    gravity
        Optional self-weight.
    """

    forces: Sequence[tuple[int, Sequence[float]]] = ()
    moments: Sequence[tuple[int, Sequence[float]]] = ()
    gravity: Gravity | None = field(default=None)

    @property
    def is_empty(self) -> bool:
        """True when there is no load at all."""
        return not self.forces and not self.moments and self.gravity is None
