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

__all__ = ["Modes", "StabilityResult", "mode_fields", "stability", "symmetry_action"]


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


def symmetry_action(objective: RodObjective, rigid: FloatArray, gradient: FloatArray) -> FloatArray:
    """The part of ``H rigid`` that the rigid motions' symmetry implies at the base of
    ``objective``, whether or not it is an equilibrium ``(n_free, k)``.

    An energy invariant under the rotations of the body satisfies ``E(R x) = E(x)``;
    differentiating ``grad E(R(t) x) = R(t) grad E(x)`` at ``t = 0`` gives
    ``H (w x r) = w x grad E`` on the node positions (twist angles, scalars, are unchanged), and
    ``H t = 0`` for a translation. At an equilibrium this vanishes; away from one (the lift
    probe's weightless lattice, analysed in the pose it rests in on the floor) it is what makes
    a straight rigid rotation look curved (``-grad E . (w x (w x r))``) although the energy is
    the same along the rotation itself. Whatever ``H rigid`` has beyond it is what breaks the
    symmetry: dead loads, moments, supports. Each candidate's rotation ``w`` is recovered from
    its node displacements (least squares over ``u_i = t + w x (x_i - c)``).
    """
    lay = objective.model.layout
    k = rigid.shape[1]
    free = objective.free
    if k == 0:
        return np.zeros((len(free), 0))
    full = np.zeros((lay.count, k))
    full[free] = rigid
    dofs = lay.pos[:, None] + np.arange(3)
    disp = full[dofs]  # (N, 3, k)
    x = objective.base.positions
    r = x - x.mean(axis=0)
    n = len(x)
    A = np.zeros((n, 3, 6))
    A[:, :, :3] = np.eye(3)
    # w x r = -[r]x w
    A[:, 0, 4], A[:, 0, 5] = r[:, 2], -r[:, 1]
    A[:, 1, 3], A[:, 1, 5] = -r[:, 2], r[:, 0]
    A[:, 2, 3], A[:, 2, 4] = r[:, 1], -r[:, 0]
    coef = np.linalg.lstsq(A.reshape(3 * n, 6), disp.reshape(3 * n, k), rcond=None)[0]
    omega = coef[3:].T  # (k, 3)
    g = np.zeros(lay.count)
    g[free] = gradient
    gpos = g[dofs]  # (N, 3)
    act = np.zeros((lay.count, k))
    for j in range(k):
        act[dofs, j] = np.cross(omega[j], gpos)
    return act[free]


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
    rigid = obj.rigid_modes()
    spec = analyse_hessian(
        H,
        obj.metric(),
        rigid,
        count=int(count),
        modes=True,
        tol=tol,
        rigid_action=symmetry_action(obj, rigid, g),
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
