"""Static equilibrium of a rod network: the public entry point of the rod solver."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.contact.potential import Contact, ContactPotential
from rotomorph.contact.stacked import StackedContact
from rotomorph.errors import ConvergenceError
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import NewtonOptions, minimize
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.result import Status
from rotomorph.solve.stability import Modes, mode_fields


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
        Total potential energy at equilibrium (N mm): elastic energy, minus the work of dead
        forces and gravity on the absolute node positions (so equilibria of one model under the
        same loads compare directly), plus the contact barrier and lagged friction terms when
        contact is on.
    residual
        Weighted gradient norm relative to the problem's force scale.
    wall_time
        Seconds spent in the solve.
    contact
        The contact model bound to the network when the solve had contact (None otherwise):
        ``result.contact.forces(result.state)``, ``.clearance(...)``,
        ``.active_contacts(...)`` (node positions also do, except for a printed stack's
        contact, :class:`~rotomorph.contact.stacked.StackedContact`, which reads its layers
        off the state's material frames).
    stable
        True: certified a local minimum (the Hessian on the free DOFs, rigid motions removed,
        is positive definite or neutral within round-off; see
        :mod:`rotomorph.solve.stability`). False only when ``NewtonOptions.check_stability``
        was switched off and the point is unchecked.
    eigenvalues
        Lowest Hessian eigenvalues at the equilibrium, ascending (N/mm²; how many:
        ``NewtonOptions.eigenvalues``).
    modes
        Their mode shapes when ``NewtonOptions.keep_modes`` is set, else None.
    escapes
        Steps the solver took off unstable equilibria (saddles) on the way.
    max_axial_strain
        Largest ``|l / l̄ − 1|`` over the edges: stretch or shortening of the centre line
        against its natural (rest) length. The rod model's stretching law is a small-strain
        law; a state far beyond a few per cent (e.g. a compressive dead load that flipped the
        rod and now pulls it to several times its length) is not physical
        (:mod:`rotomorph.io.validity` flags it).
    """

    state: State
    status: Status
    iterations: int
    factorizations: int
    energy: float
    residual: float
    wall_time: float
    contact: ContactPotential | StackedContact | None = None
    stable: bool = False
    eigenvalues: FloatArray = field(default_factory=lambda: np.zeros(0))
    modes: Modes | None = None
    escapes: int = 0
    max_axial_strain: float = 0.0

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

    The equilibrium returned is certified a local minimum (``result.stable``); from an
    unstable one (e.g. a perfectly straight column above its Euler load) the solver steps
    along the direction of negative curvature and goes on (:mod:`rotomorph.solve.newton`).

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
        If Newton's method does not converge, stalls at its round-off floor above ``rtol``
        (``Status.STALLED``) or ends on an equilibrium it cannot leave although it is unstable
        (``Status.SADDLE``); ``error.result`` holds the diagnostics
        (:class:`~rotomorph.solve.result.NewtonResult`) and ``error.state`` the last iterate.
    """
    t0 = time.perf_counter()
    state = model.reference_state() if initial is None else initial
    obj = RodObjective(model, state, supports or Supports(), loads or Loads(), contact)
    res = minimize(obj, obj.vector(), options)
    final = obj.base
    if res.status is not Status.CONVERGED:
        hint = _HINTS.get(res.status, _HINTS[Status.MAX_ITERATIONS])
        err = ConvergenceError(
            f"static solve did not converge: {res.status.value} after {res.iterations} "
            f"iterations (residual {res.residual:.3e}); {hint}",
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
        stable=bool(res.stable),
        eigenvalues=res.eigenvalues,
        modes=None if res.modes is None else mode_fields(obj, res.modes),
        escapes=res.escapes,
        max_axial_strain=max_axial_strain(model, final),
    )


def max_axial_strain(model: Model, state: State) -> float:
    """Largest ``|l / l̄ − 1|`` over the edges of ``state`` (l̄: the model's rest lengths)."""
    pos = np.asarray(state.positions)
    edges = model.network.edges
    length = np.linalg.norm(pos[edges[:, 1]] - pos[edges[:, 0]], axis=1)
    rest = np.asarray(model.rest_length, dtype=float)
    return float(np.max(np.abs(length / rest - 1.0))) if len(rest) else 0.0


_HINTS = {
    Status.MAX_ITERATIONS: "try load stepping (continuation), a larger "
    "NewtonOptions.max_iterations, or check supports and loads",
    Status.STALLED: "the residual is at its round-off floor (very stiff axial springs "
    "against small loads); raise NewtonOptions.rtol above the residual shown",
    Status.SADDLE: "the equilibrium reached is unstable and no energy-lowering step along "
    "its negative curvature was found; perturb the initial state or step the load",
}
