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
:math:`\partial g/\partial p` (internal forces are balanced), so the solve uses
:math:`H + \delta M` with a tiny relative shift :math:`\delta`: the rigid components of
:math:`\lambda` it leaves do not change the gradient. The same factorisation certifies that the
equilibrium is a minimum (it fails when :math:`H` has a negative eigenvalue).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from rotomorph._typing import FloatArray
from rotomorph.rod.model import Model
from rotomorph.rod.sensitivity import NaturalSensitivity, natural_sensitivity
from rotomorph.rod.state import State
from rotomorph.solve.linalg import BandedMatrix
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.objective import RodObjective

__all__ = ["AdjointResult", "NotAMinimumError", "adjoint"]


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
    shift: float = 1e-10,
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
    shift
        Relative shift of the metric added to ``H`` (module docstring).

    Raises
    ------
    NotAMinimumError
        ``H + shift`` is not positive definite: the equilibrium is unstable.
    """
    obj = RodObjective(model, state, supports or Supports(), loads or Loads())
    q = obj.vector()
    _, _, H = obj.evaluate(q, True, 1)
    A = _hessian_csc(H)
    metric = obj.metric()
    scale = float(np.max(np.abs(A.diagonal())) / max(float(np.max(metric)), 1e-300))
    A = (A + sp.diags(shift * scale * metric)).tocsc()
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
    lam = np.zeros(model.layout.count)
    lam[obj.free] = lam_free
    return AdjointResult(adjoint=lam, sensitivity=natural_sensitivity(model, state, lam))
