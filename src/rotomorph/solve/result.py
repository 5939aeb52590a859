"""Result records of the solvers."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import Enum

import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import FloatArray


class Status(Enum):
    """How a solve ended. Only ``CONVERGED`` is success; an iteration limit is never success."""

    CONVERGED = "converged"
    MAX_ITERATIONS = "max_iterations"
    LINE_SEARCH_FAILED = "line_search_failed"
    NOT_FINITE = "not_finite"
    STALLED = "stalled"  # whole Newton steps no longer lower a residual above rtol (round-off)
    SADDLE = "saddle"  # an equilibrium with negative curvature that could not be left


@compact_display()
@dataclass(frozen=True, eq=False)
class NewtonResult:
    """Outcome of :func:`rotomorph.solve.newton.minimize`.

    Attributes
    ----------
    x
        Final iterate.
    status
        How the iteration ended.
    iterations
        Newton iterations taken (Hessian evaluations).
    factorizations
        Linear factorizations (including rejected shifted attempts).
    energy
        Objective value at ``x``.
    residual
        Weighted gradient norm at ``x`` divided by the force scale (dimensionless).
    decrement
        Last Newton decrement ``-g.d`` divided by the energy scale (dimensionless).
    history
        Per-iteration ``(energy, residual, step length, shift)`` rows.
    stable
        Whether ``x`` was certified a local minimum on the free DOFs with rigid modes removed
        (:mod:`rotomorph.solve.spectrum`); None when not checked (not converged, or disabled).
    eigenvalues
        Lowest eigenvalues of the Hessian at ``x`` in the solver's metric, ascending (N/mm²
        for rods); empty when not computed.
    modes
        Their eigenvectors ``(n, k)`` when asked for (``NewtonOptions.keep_modes``).
    escapes
        Steps taken along a direction of negative curvature from an unstable equilibrium.
    residual_floor
        The objective's estimate of the residual's round-off floor (relative, like
        ``residual``); convergence means ``residual <= max(rtol, residual_floor)``.
    """

    x: FloatArray
    status: Status
    iterations: int
    factorizations: int
    energy: float
    residual: float
    decrement: float
    history: FloatArray = field(default_factory=lambda: np.zeros((0, 4)))
    stable: bool | None = None
    eigenvalues: FloatArray = field(default_factory=lambda: np.zeros(0))
    modes: FloatArray | None = None
    escapes: int = 0
    residual_floor: float = 0.0

    @property
    def converged(self) -> bool:
        """True when the status is ``CONVERGED``."""
        return self.status is Status.CONVERGED
