r"""Sensitivity of the equilibrium equations to the natural values of a rod network.

The gradient of the elastic energy, :math:`g(x; p)`, depends on the natural (rest) quantities
``p`` = (integrated natural curvatures :math:`\bar\kappa_1, \bar\kappa_2`, natural twist
:math:`\bar\tau` per stencil, rest length :math:`\bar l` per edge). Adjoint design needs the
products :math:`\lambda^T \partial g/\partial p` for one adjoint vector :math:`\lambda`; this
module gives them exactly, from the same closed-form strain gradients the energy kernels use.

For a stencil with energy :math:`E = \frac{1}{2\bar l_v}\sum_c B_c(\kappa_c - \bar\kappa_c)^2`
(Bergou et al. 2008; the Voronoi length :math:`\bar l_v = (\bar l_e + \bar l_f)/2`):

* :math:`\partial g/\partial\bar\kappa_c = -(B_c/\bar l_v)\,\nabla\kappa_c`, so
  :math:`\lambda^T\partial g/\partial\bar\kappa_c = -(B_c/\bar l_v)\,(\nabla\kappa_c\cdot\lambda)`;
* :math:`\partial g/\partial\bar l_v = -g_v/\bar l_v` (``g_v`` the stencil's gradient), split
  half-half onto the stencil's two edges' rest lengths;
* stretching :math:`E_j = \frac{EA}{2\bar l}(|e| - \bar l)^2` gives
  :math:`\partial g_j/\partial\bar l = \mp EA\,(|e|/\bar l^2)\,\hat t` on the edge's two nodes.

All derivatives are at fixed positions, twist angles and (time-parallel) frames, which is what
the adjoint of an equilibrium needs.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph._typing import FloatArray
from rotomorph.rod.kernels import bend_twist_stencil
from rotomorph.rod.model import Model
from rotomorph.rod.state import State

__all__ = ["NaturalSensitivity", "natural_sensitivity"]


@njit(cache=True)
def _products(
    pos,
    theta,
    m1,
    m2,
    mref,
    st_nodes,
    st_edge_e,
    st_edge_f,
    st_sign_e,
    st_sign_f,
    params,
    edges,
    axial,
    rest,
    pos_dof,
    theta_dof,
    lam,
    out_k,
    out_l,
):  # pragma: no cover - compiled
    D = np.empty((3, 3, 3))
    gk = np.empty((3, 11))
    g = np.empty(11)
    H = np.empty((11, 11))
    loc = np.empty(11)
    for k in range(out_l.shape[0]):
        out_l[k] = 0.0
    for s in range(st_nodes.shape[0]):
        n0 = st_nodes[s, 0]
        n1 = st_nodes[s, 1]
        n2 = st_nodes[s, 2]
        ea = st_edge_e[s]
        fb = st_edge_f[s]
        se = st_sign_e[s]
        sf = st_sign_f[s]
        m2e = (se * m2[ea, 0], se * m2[ea, 1], se * m2[ea, 2])
        m2f = (sf * m2[fb, 0], sf * m2[fb, 1], sf * m2[fb, 2])
        tw = sf * theta[fb] - se * theta[ea] + mref[s]
        bend_twist_stencil(
            (pos[n0, 0], pos[n0, 1], pos[n0, 2]),
            (pos[n1, 0], pos[n1, 1], pos[n1, 2]),
            (pos[n2, 0], pos[n2, 1], pos[n2, 2]),
            (m1[ea, 0], m1[ea, 1], m1[ea, 2]),
            m2e,
            (m1[fb, 0], m1[fb, 1], m1[fb, 2]),
            m2f,
            tw,
            params[s, 0],
            params[s, 1],
            params[s, 2],
            params[s, 3],
            params[s, 4],
            params[s, 5],
            params[s, 6],
            g,
            H,
            True,
            0,
            D,
            gk,
        )
        for k in range(3):
            loc[k] = lam[pos_dof[n0] + k]
            loc[4 + k] = lam[pos_dof[n1] + k]
            loc[8 + k] = lam[pos_dof[n2] + k]
        loc[3] = se * lam[theta_dof[ea]]
        loc[7] = sf * lam[theta_dof[fb]]
        inv_l = 1.0 / params[s, 3]
        gl = 0.0
        for c in range(3):
            acc = 0.0
            for i in range(11):
                acc += gk[c, i] * loc[i]
            out_k[s, c] = -params[s, c] * inv_l * acc
        for i in range(11):
            gl += g[i] * loc[i]
        # dE/dl_v = -E/l_v at fixed integrated naturals; its x-gradient is -g/l_v
        out_l[ea] += -0.5 * inv_l * gl
        out_l[fb] += -0.5 * inv_l * gl
    for j in range(edges.shape[0]):
        a = edges[j, 0]
        b = edges[j, 1]
        e0 = pos[b, 0] - pos[a, 0]
        e1 = pos[b, 1] - pos[a, 1]
        e2 = pos[b, 2] - pos[a, 2]
        ln = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        c = -axial[j] * ln / (rest[j] * rest[j]) / ln
        dl = (
            (lam[pos_dof[b]] - lam[pos_dof[a]]) * e0
            + (lam[pos_dof[b] + 1] - lam[pos_dof[a] + 1]) * e1
            + (lam[pos_dof[b] + 2] - lam[pos_dof[a] + 2]) * e2
        )
        out_l[j] += c * dl


class NaturalSensitivity:
    """Products ``lambda^T dg/dp`` for the natural values of ``model`` at ``state``.

    Attributes
    ----------
    curvature1, curvature2, twist
        ``(S,)`` products with the *integrated* natural curvatures and twist of each stencil
        (N·mm per unit dimensionless angle... i.e. units of ``lambda`` times N).
    rest_length
        ``(E,)`` products with each edge's rest length at fixed integrated naturals (N/mm times
        units of ``lambda``).
    """

    def __init__(self, k: FloatArray, rest: FloatArray) -> None:
        self.curvature1 = k[:, 0].copy()
        self.curvature2 = k[:, 1].copy()
        self.twist = k[:, 2].copy()
        self.rest_length = rest


def natural_sensitivity(model: Model, state: State, lam: FloatArray) -> NaturalSensitivity:
    """Exact ``lambda^T dg/dp`` of the energy gradient w.r.t. the natural values.

    Parameters
    ----------
    model
        The rod network (stiffnesses, natural values, rest lengths).
    state
        The configuration (positions in mm, twist angles, frames) where ``g`` is linearised.
    lam
        Adjoint vector over *all* DOFs of ``model.layout`` (``layout.count``,), in the layout's
        order (positions in mm, twist angles in rad).

    Returns
    -------
    NaturalSensitivity
        Products with the integrated natural curvatures/twist (per stencil) and with the rest
        lengths (per edge).
    """
    lam = np.ascontiguousarray(lam, dtype=float)
    lay, st, net = model.layout, model.stencils, model.network
    if lam.shape != (lay.count,):
        raise ValueError(f"lam must have shape ({lay.count},); got {lam.shape}")
    m1, m2 = state.material_directors()
    b1, b2, c = model.stencil_stiffness
    k1, k2, tw = model.integrated_natural()
    params = np.ascontiguousarray(np.stack([b1, b2, c, model.voronoi_length, k1, k2, tw], 1))
    out_k = np.zeros((st.count, 3))
    out_l = np.zeros(net.n_edges)
    _products(
        np.ascontiguousarray(state.positions),
        np.ascontiguousarray(state.theta),
        m1,
        m2,
        np.ascontiguousarray(state.reference_twist),
        np.ascontiguousarray(st.nodes),
        np.ascontiguousarray(st.edge_e),
        np.ascontiguousarray(st.edge_f),
        np.ascontiguousarray(st.sign_e, dtype=float),
        np.ascontiguousarray(st.sign_f, dtype=float),
        params,
        np.ascontiguousarray(net.edges),
        np.ascontiguousarray(model.axial_stiffness, dtype=float),
        np.ascontiguousarray(model.rest_length, dtype=float),
        np.ascontiguousarray(lay.pos),
        np.ascontiguousarray(lay.theta),
        lam,
        out_k,
        out_l,
    )
    return NaturalSensitivity(out_k, out_l)
