r"""Stability and lowest modes of an equilibrium of any rod network (filament, ring, lattice).

An equilibrium is *stable* when every small motion that the supports allow raises the total
potential energy: the Hessian of the free degrees of freedom (node positions in mm, twist angles
in rad), with the rigid motions of an unsupported body removed, is positive definite. The lowest
eigenvalues ``lambda`` of ``H v = lambda M v`` measure how far from losing stability it is; ``M``
is the solver's lumped metric (the Voronoi length of each node for its three positions, ``l^3``
for the twist angle of an edge of length ``l``), so ``lambda`` is a stiffness per unit length
squared (N/mm², i.e. MPa) and, for a rod of unit mass per length, the square of a natural
frequency. A negative ``lambda`` means unstable, and its mode is the way the structure leaves:
a straight column above its Euler load has one, with the buckling shape as its mode.

:func:`stability` analyses any configuration; :func:`rotomorph.solve.static.solve_static`
certifies every equilibrium it returns in the same way (:mod:`rotomorph.solve.spectrum`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.rod.model import Model
from rotomorph.rod.state import State
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.spectrum import analyse_hessian

__all__ = ["Modes", "StabilityResult", "mode_fields", "stability"]


@dataclass(frozen=True, eq=False)
class Modes:
    """Eigenmodes of a rod network as fields on its nodes and edges.

    Attributes
    ----------
    displacements
        Node displacement of each mode ``(k, N, 3)`` (mm per unit metric norm; zero at supported
        DOFs).
    twist
        Twist-angle change of each edge ``(k, E)`` (rad per unit metric norm).
    """

    displacements: FloatArray
    twist: FloatArray

    @property
    def count(self) -> int:
        """Number of modes k."""
        return int(self.displacements.shape[0])


@dataclass(frozen=True, eq=False)
class StabilityResult:
    """Outcome of :func:`stability`.

    Attributes
    ----------
    stable
        True when the Hessian on the free DOFs (rigid motions removed) is positive definite, or
        its lowest eigenvalue is neutral within round-off.
    eigenvalues
        Lowest eigenvalues ``(k,)``, ascending (N/mm²; see the module docstring).
    modes
        Their mode shapes.
    rigid_modes
        Rigid motions removed (6 for an unsupported body, 0 with supports).
    certificate
        ``"cholesky"`` (the unshifted factorization of the reduced Hessian succeeded) or
        ``"eigenvalues"``.
    gradient_norm
        Norm of the free-DOF gradient at the analysed state (N; N mm for twist angles): near 0
        at an equilibrium; stability of a non-equilibrium is meaningless.
    """

    stable: bool
    eigenvalues: FloatArray
    modes: Modes
    rigid_modes: int
    certificate: str
    gradient_norm: float


def mode_fields(objective: RodObjective, vectors: FloatArray) -> Modes:
    """Free-DOF vectors ``(n_free, k)`` of ``objective`` as node and edge fields."""
    lay = objective.model.layout
    vectors = np.asarray(vectors, dtype=float)
    k = vectors.size // max(len(objective.free), 1)
    vectors = vectors.reshape(len(objective.free), k)
    full = np.zeros((lay.count, k))
    full[objective.free] = vectors
    disp = full[(lay.pos[:, None] + np.arange(3)).ravel()].T.reshape(k, len(lay.pos), 3)
    return Modes(displacements=disp, twist=full[lay.theta].T.copy())


def stability(
    model: Model,
    state: State | None = None,
    supports: Supports | None = None,
    loads: Loads | None = None,
    *,
    count: int = 6,
    tol: float = 1e-12,
) -> StabilityResult:
    """Lowest eigenvalues and modes of the Hessian of ``model`` at ``state``.

    Parameters
    ----------
    model
        The rod network (its natural fields and stiffnesses).
    state
        The configuration to analyse, normally an equilibrium (``solve_static(...).state``);
        default the model's reference (printed) state.
    supports, loads
        As for :func:`~rotomorph.solve.static.solve_static` (the same ones as the solve).
    count
        Number of lowest eigenvalues and modes (fewer when the problem is smaller). 0: the
        verdict only, from one unshifted Cholesky factorization of the reduced Hessian; the
        lowest eigenvalue and its mode are computed only when that factorization fails (to
        decide), otherwise ``eigenvalues`` and ``modes`` are empty.
    tol
        Eigenvalues above ``-tol`` times the largest diagonal ratio ``H_ii / M_ii`` count as
        neutral (stable).

    Returns
    -------
    StabilityResult

    Examples
    --------
    A straight clamped–free column is compressed along its axis by ``f`` times its Euler load
    ``pi^2 B / (4 L^2)``. Solved without the stability check, it stays straight; that straight
    equilibrium is stable below the Euler load and unstable above it:

    >>> import numpy as np
    >>> from rotomorph.rod.model import Model
    >>> from rotomorph.solve.loads import Loads, Supports
    >>> from rotomorph.solve.newton import NewtonOptions
    >>> from rotomorph.solve.static import solve_static
    >>> s = np.linspace(0.0, 10.0, 21)
    >>> rod = Model.chain(np.c_[s, 0 * s, 0 * s], bending_stiffness1=0.01,
    ...                   bending_stiffness2=0.01, twist_stiffness=0.008, axial_stiffness=10.0)
    >>> p_cr = np.pi**2 * 0.01 / (4 * 10.0**2)
    >>> for f in (0.8, 1.2):
    ...     supports, loads = Supports.clamp_ends(21), Loads(forces=[(20, (-f * p_cr, 0, 0))])
    ...     straight = solve_static(rod, supports, loads,
    ...                             options=NewtonOptions(check_stability=False))
    ...     res = stability(rod, straight.state, supports, loads, count=2)
    ...     print(f, res.stable, bool(res.eigenvalues[0] > 0))
    0.8 True True
    1.2 False False
    """
    if int(count) != count or count < 0:
        raise InvalidParameterError("count", f"must be an integer >= 0; got {count}")
    state = model.reference_state() if state is None else state
    obj = RodObjective(model, state, supports or Supports(), loads or Loads())
    _, g, H = obj.evaluate(obj.vector(), True, 1)
    spec = analyse_hessian(
        H, obj.metric(), obj.rigid_modes(), count=int(count), modes=True, tol=tol
    )
    vectors = np.zeros((len(obj.free), 0)) if spec.modes is None else spec.modes
    return StabilityResult(
        stable=spec.stable,
        eigenvalues=spec.eigenvalues,
        modes=mode_fields(obj, vectors),
        rigid_modes=spec.rigid,
        certificate=spec.certificate,
        gradient_norm=float(np.linalg.norm(g)),
    )
