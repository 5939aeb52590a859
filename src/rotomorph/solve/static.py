"""Static equilibrium of a rod network: the public entry point of the rod solver."""

from __future__ import annotations

import time
from dataclasses import dataclass

from rotomorph._typing import FloatArray
from rotomorph.contact.potential import Contact, ContactPotential
from rotomorph.errors import ConvergenceError
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import NewtonOptions, minimize
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.result import Status


@dataclass(frozen=True, eq=False)
class StaticResult:
    """Equilibrium of a rod network.

    Attributes
    ----------
    state
        Equilibrium configuration (positions in mm, twist angles, frames).
    status
        ``Status.CONVERGED`` (anything else raises :class:`ConvergenceError`).
    iterations, factorizations
        Newton iterations and linear factorizations used.
    energy
        Total potential energy at equilibrium (N mm; elastic minus the work of dead loads
        relative to the last Newton base).
    residual
        Weighted gradient norm relative to the problem's force scale.
    wall_time
        Seconds spent in the solve.
    contact
        The contact model bound to the network when the solve had contact (None otherwise):
        ``result.contact.forces(result.positions)``, ``.clearance(...)``,
        ``.active_contacts(...)``.
    """

    state: State
    status: Status
    iterations: int
    factorizations: int
    energy: float
    residual: float
    wall_time: float
    contact: ContactPotential | None = None

    @property
    def positions(self) -> FloatArray:
        """Equilibrium node positions ``(N, 3)`` (mm)."""
        return self.state.positions


def solve_static(
    model: Model,
    supports: Supports | None = None,
    loads: Loads | None = None,
    initial: State | None = None,
    options: NewtonOptions | None = None,
    contact: Contact | None = None,
) -> StaticResult:
    """Find a stable equilibrium of ``model`` under ``supports`` and ``loads``.

    Parameters
    ----------
    model
        The rod network.
    supports
        Clamped edges, pinned nodes; default free–free (rigid motions are harmless: the
        modified-Newton shift handles the singular directions, no DOF is pinned for them).
    loads
        Dead point forces, moments and gravity.
    initial
        Starting configuration (default: the model's reference state). Continuation passes the
        previous equilibrium here.
    options
        Newton settings.
    contact
        Self-contact and rigid obstacles (:class:`~rotomorph.contact.Contact`); no iterate
        ever interpenetrates. The initial state must be separated.

    Raises
    ------
    InfeasibleContactError
        If the initial state already touches or interpenetrates.
    ConvergenceError
        If Newton's method does not converge; ``error.result`` holds the diagnostics
        (:class:`~rotomorph.solve.result.NewtonResult`) and ``error.state`` the last iterate.
    """
    t0 = time.perf_counter()
    state = model.reference_state() if initial is None else initial
    obj = RodObjective(model, state, supports or Supports(), loads or Loads(), contact)
    res = minimize(obj, obj.vector(), options)
    final = obj.base
    if res.status is not Status.CONVERGED:
        err = ConvergenceError(
            f"static solve did not converge: {res.status.value} after {res.iterations} "
            f"iterations (residual {res.residual:.3e}); try load stepping (continuation), a "
            "larger NewtonOptions.max_iterations, or check supports and loads",
            result=res,
        )
        err.state = final  # type: ignore[attr-defined]
        raise err
    return StaticResult(
        state=final,
        status=res.status,
        iterations=res.iterations,
        factorizations=res.factorizations,
        energy=res.energy,
        residual=res.residual,
        wall_time=time.perf_counter() - t0,
        contact=obj.contact,
    )
