r"""Lagged Coulomb friction as a smooth potential (IPC's friction for a quasi-static step).

At the start of a load step (the *lag* state :math:`x^0`, the previous equilibrium) every
contact ``k`` carrying normal force fixes its normal force magnitude :math:`\lambda_k`, its
closest-point weights ``w`` (as in :mod:`rotomorph.contact.distance`) and an orthonormal
tangent basis :math:`T_k` (3 × 2) perpendicular to the contact normal. The tangential slip of
the contact during the step is linear in the positions,

.. math::  u_k(x) = T_k^T \textstyle\sum_n w_n\,(x_n - x_n^0) \in \mathbb{R}^2,

and the friction potential is :math:`D = \sum_k \mu\,\lambda_k\, f_0(|u_k|)` with the
smoothed magnitude :math:`f_0(y) = -y^3/(3\epsilon^2) + y^2/\epsilon + \epsilon/3` for
:math:`y < \epsilon` and :math:`f_0(y) = y` beyond (``ε`` the slip distance over which
sticking turns to sliding). Its force :math:`-\mu\lambda_k f_1(|u|)\,\hat u` with
:math:`f_1 = f_0'` never exceeds the Coulomb bound :math:`\mu\lambda_k` and opposes the slip:
Li et al., "Incremental Potential Contact", ACM TOG 39(4) 49 (2020), § 5 (there ``u`` is a
velocity times the time step; in statics the step is the load step). For fixed lagged
quantities the gradient and Hessian below are exact; the Hessian is positive semidefinite.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotomorph._typing import FloatArray, IntArray

__all__ = ["FrictionLag", "friction_energy", "lag_change", "mollifier"]


@dataclass(frozen=True, eq=False)
class FrictionLag:
    """The lagged friction data of one load step.

    Attributes
    ----------
    nodes
        Node indices of each contact ``(K, 4)`` into the extended point array (a floor contact
        repeats its node with zero weights on the copies).
    weights
        Closest-point weights ``(K, 4)`` (``1-s, s, -(1-t), -t``).
    bases
        Tangent bases ``(K, 3, 2)``.
    normal_force
        Lagged normal force magnitudes ``(K,)`` (N).
    start
        Positions of the lag state (extended array ``(M, 3)``, mm).
    coefficient
        Friction coefficient μ.
    slip
        Smoothing slip ε (mm).
    """

    nodes: IntArray
    weights: FloatArray
    bases: FloatArray
    normal_force: FloatArray
    start: FloatArray
    coefficient: float
    slip: float

    @property
    def count(self) -> int:
        """Number of lagged contacts."""
        return len(self.normal_force)


def mollifier(y: FloatArray, eps: float) -> tuple[FloatArray, FloatArray, FloatArray]:
    """``f0(y)``, ``f1(y) / y`` and ``f1'(y)`` of the smoothed magnitude (y ≥ 0, mm)."""
    y = np.asarray(y, dtype=float)
    inner = y < eps
    f0 = np.where(inner, -(y**3) / (3 * eps**2) + y**2 / eps + eps / 3, y)
    f1_over_y = np.where(inner, -y / eps**2 + 2 / eps, 1.0 / np.maximum(y, 1e-300))
    df1 = np.where(inner, -2 * y / eps**2 + 2 / eps, 0.0)
    return f0, f1_over_y, df1


def friction_energy(
    lag: FrictionLag, x: FloatArray, need_grad: bool, need_hess: bool
) -> tuple[float, FloatArray | None, FloatArray | None]:
    """Friction potential (N mm), gradient ``(M, 3)`` and local Hessians ``(K, 12, 12)``."""
    if lag.count == 0:
        return 0.0, (np.zeros_like(x) if need_grad else None), np.zeros((0, 12, 12))
    dx = x[lag.nodes] - lag.start[lag.nodes]  # (K, 4, 3)
    rel = np.einsum("kn,knc->kc", lag.weights, dx)
    u = np.einsum("kcj,kc->kj", lag.bases, rel)  # (K, 2)
    y = np.linalg.norm(u, axis=1)
    f0, f1y, df1 = mollifier(y, lag.slip)
    c = lag.coefficient * lag.normal_force
    energy = float(np.sum(c * f0))
    grad = hloc = None
    # J (K, 2, 12) = T^T (w_n I) per node
    J = np.einsum("kcj,kn->kjnc", lag.bases, lag.weights).reshape(-1, 2, 12)
    if need_grad:
        gu = (c * f1y)[:, None] * u  # dD/du
        g12 = np.einsum("kj,kjm->km", gu, J).reshape(-1, 4, 3)
        grad = np.zeros_like(x)
        np.add.at(grad, lag.nodes.ravel(), g12.reshape(-1, 3))
    if need_hess:
        uhat = u / np.maximum(y, 1e-300)[:, None]
        # d2 f0(|u|) = (f1/y) I + (f1' - f1/y) uhat uhat^T
        Hu = f1y[:, None, None] * np.eye(2) + (df1 - f1y)[:, None, None] * np.einsum(
            "ki,kj->kij", uhat, uhat
        )
        Hu *= c[:, None, None]
        hloc = np.transpose(J, (0, 2, 1)) @ Hu @ J  # J^T Hu J per contact
    return energy, grad, hloc


def _normal_forces(lag: FrictionLag) -> FloatArray:
    """Each lagged contact's normal force vector ``lambda n`` ``(K, 3)`` (N; ``n`` the normal the
    right-handed tangent basis is taken about)."""
    return lag.normal_force[:, None] * np.cross(lag.bases[:, :, 0], lag.bases[:, :, 1])


def lag_change(old: FrictionLag, new: FrictionLag) -> float:
    """How much the lagged normal forces and normals changed from ``old`` to ``new``
    (dimensionless): ``sum_k |lambda_k n_k (new) - lambda_k n_k (old)|`` over the larger total
    lagged force, contacts matched by their nodes (one lagged in only one of the two counts with
    its whole force). 0 when nothing is lagged in either. The tangent plane is the one normal
    to ``n`` whatever its in-plane basis, so the normal force vector holds everything the
    friction potential depends on besides the closest points."""
    total = max(float(old.normal_force.sum()), float(new.normal_force.sum()))
    if total == 0.0:
        return 0.0
    keys, index = np.unique(np.concatenate([old.nodes, new.nodes]), axis=0, return_inverse=True)
    diff = np.zeros((len(keys), 3))
    np.add.at(diff, index.reshape(-1)[: old.count], -_normal_forces(old))
    np.add.at(diff, index.reshape(-1)[old.count :], _normal_forces(new))
    return float(np.linalg.norm(diff, axis=1).sum()) / total
