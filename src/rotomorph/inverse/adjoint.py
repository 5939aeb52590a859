r"""Gradients through an equilibrium by the adjoint method.

A design ``p`` sets the natural values of a rod network (integrated natural curvatures and
twist per stencil, rest lengths per edge); its equilibrium :math:`x^*(p)` solves
:math:`g(x; p) = \nabla_x E(x; p) = 0`. For an objective :math:`J(x^*(p), p)`,

.. math::

    \frac{dJ}{dp} = \frac{\partial J}{\partial p} - \lambda^T \frac{\partial g}{\partial p},
    \qquad H\lambda = \frac{\partial J}{\partial x},

with :math:`H = \partial g/\partial x` the Hessian at the equilibrium: one extra linear solve
per gradient, whatever the number of design variables (e.g. Pérez et al., *ACM Trans. Graph.*
34, 2015; Panetta et al., *ACM Trans. Graph.* 38, 2019). The products
:math:`\lambda^T\partial g/\partial p` come exactly from
:func:`rotomorph.rod.sensitivity.natural_sensitivity`.

A free body's Hessian is singular along rigid motions; an objective that is invariant under
rigid motions has :math:`\partial J/\partial x` orthogonal to them, and so has every
:math:`\partial g/\partial p` (internal forces are balanced), so the solve factorises
:math:`H + \delta M` with a tiny relative shift :math:`\delta`: the rigid components of
:math:`\lambda` it leaves do not change the gradient. The solution is then refined
iteratively against :math:`H` itself, which removes the bias the shift would otherwise leave
along soft modes (relative :math:`\delta/\mu` on an eigenvalue :math:`\mu`). The same
factorisation certifies that the equilibrium is a minimum (it fails when :math:`H` has a
negative eigenvalue).

Contact (:class:`~rotomorph.contact.Contact`: self-contact and a floor) is part of ``g`` and
``H``: the barrier's gradient and Hessian join the rod's at the equilibrium, as in the forward
Newton solve. The barrier depends on the positions only, so it adds nothing to
:math:`\partial g/\partial p` — provided its stiffness is fixed (give
``Contact.stiffness``; the default is scaled from the natural values). Only frictionless
contact is a conservative term: lagged friction is not a gradient and is refused. A free body
on a frictionless floor keeps its three rigid motions along the floor, which ``H`` leaves
singular and the shift handles as above. Gravity (a dead load per unit *rest* length) does
depend on the rest lengths: its term :math:`-\tfrac12 w_j \hat d` on both nodes of edge
:math:`j` enters :math:`\partial g/\partial l_j`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rotomorph._typing import FloatArray
from rotomorph.contact.potential import Contact
from rotomorph.errors import InvalidParameterError
from rotomorph.rod.model import Model
from rotomorph.rod.sensitivity import NaturalSensitivity, natural_sensitivity
from rotomorph.rod.state import State
from rotomorph.solve.linalg import BandedMatrix
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.objective import RodObjective

__all__ = ["AdjointResult", "NotAMinimumError", "adjoint", "richardson_difference"]


class NotAMinimumError(RuntimeError):
    """The Hessian at the equilibrium is not positive semidefinite (an unstable state)."""


@dataclass(frozen=True, eq=False)
class AdjointResult:
    """Adjoint vector and its products with the natural-value derivatives of ``g``."""

    adjoint: FloatArray
    sensitivity: NaturalSensitivity


def _hessian_csc(H: object) -> sp.csc_matrix:
    if isinstance(H, BandedMatrix):
        return sp.csc_matrix(H.to_dense())
    csc = getattr(H, "csc", None)
    if csc is not None:
        return sp.csc_matrix(csc)
    return sp.csc_matrix(np.asarray(H))


def adjoint(
    model: Model,
    state: State,
    dj_dx: FloatArray,
    *,
    supports: Supports | None = None,
    loads: Loads | None = None,
    contact: Contact | None = None,
    shift: float = 1e-10,
    refinements: int = 8,
) -> AdjointResult:
    """Solve ``H lambda = dJ/dx`` at an equilibrium and form ``lambda^T dg/dp``.

    Parameters
    ----------
    model, state
        The rod network and its equilibrium configuration.
    dj_dx
        Gradient of the objective with respect to all DOFs of ``model.layout`` (positions in
        mm, twist angles in rad), in the layout's order.
    supports, loads
        As in the forward solve (fixed DOFs get a zero adjoint).
    contact
        As in the forward solve (frictionless; a fixed ``stiffness`` for exact gradients, see
        the module docstring): the barrier's Hessian at ``state`` is part of ``H``.
    shift
        Relative shift of the metric added to ``H`` (module docstring).
    refinements
        Most steps of iterative refinement of ``lambda`` against the unshifted ``H`` (stopped
        at a residual of 1e-14 relative): the shift must not bias the solution along soft
        modes. A lattice's softest bending modes lie far below its largest eigenvalue, the
        further the finer its rods are discretised: 5e-6 to 4e-5 of it on 3 x 3 lattices
        with 6 ghost nodes per edge, 1e-7 to 5e-7 on 5 x 5 lattices with 10, where the
        default shift alone would bias ``lambda`` by up to 1e-3 relative along them.

    Raises
    ------
    NotAMinimumError
        ``H + shift`` is not positive definite: the equilibrium is unstable.
    InvalidParameterError
        Contact with friction (not a conservative term).
    """
    if contact is not None and contact.friction > 0:
        raise InvalidParameterError(
            "Contact.friction", "the adjoint needs frictionless contact (friction=0)"
        )
    loads = loads or Loads()
    obj = RodObjective(model, state, supports or Supports(), loads, contact)
    q = obj.vector()
    _, _, H = obj.evaluate(q, True, 1)
    H0 = _hessian_csc(H)
    metric = obj.metric()
    scale = float(np.max(np.abs(H0.diagonal())) / max(float(np.max(metric)), 1e-300))
    A = (H0 + sp.diags(shift * scale * metric)).tocsc()
    b = np.asarray(dj_dx, dtype=float)[obj.free]
    try:
        lu = spla.splu(
            A, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0, options={"SymmetricMode": True}
        )
    except RuntimeError as err:  # exactly singular
        raise NotAMinimumError("the equilibrium Hessian is singular") from err
    if not (np.all(lu.U.diagonal() > 0) and np.array_equal(lu.perm_r, lu.perm_c)):
        raise NotAMinimumError(
            "the equilibrium Hessian has a negative eigenvalue: the state is not a stable minimum"
        )
    lam_free = lu.solve(b)
    # iterative refinement against the unshifted Hessian: the shift only makes the rigid modes
    # solvable; on a soft (nearly unstable) mode it would bias lambda by shift / eigenvalue
    b_norm = float(np.linalg.norm(b))
    for _ in range(refinements):
        r = b - H0 @ lam_free
        if float(np.linalg.norm(r)) <= 1e-14 * b_norm:
            break
        lam_free = lam_free + lu.solve(r)
    lam = np.zeros(model.layout.count)
    lam[obj.free] = lam_free
    # the self-weight is that of the printed filament (printed lengths), so it does not
    # depend on the natural field: no term of its own here
    return AdjointResult(adjoint=lam, sensitivity=natural_sensitivity(model, state, lam))


def richardson_difference(fun: Callable[[float], float], step: float) -> float:
    """Derivative at 0 of ``fun`` (a scalar of one variable) by extrapolated central
    differences, for checking adjoint gradients against perturbed solves.

    Central differences at steps ``2h``, ``h`` and ``h/2``; of the two pairs of neighbouring
    steps, the one whose differences agree better is Richardson-extrapolated (``O(h^4)``).
    The choice uses the differences alone: a large step's higher-order truncation and a small
    step's solver noise (which a soft equilibrium amplifies) both show up as disagreement.
    """
    if not (np.isfinite(step) and step > 0):
        raise ValueError(f"step must be > 0; got {step}")
    d = [(fun(h) - fun(-h)) / (2.0 * h) for h in (2.0 * step, step, 0.5 * step)]
    coarse, fine = abs(d[0] - d[1]), abs(d[1] - d[2])
    return (4.0 * d[1] - d[0]) / 3.0 if coarse <= fine else (4.0 * d[2] - d[1]) / 3.0
