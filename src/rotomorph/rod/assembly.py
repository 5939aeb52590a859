"""Compiled assembly of a rod network's energy, gradient and Hessian.

The network is a list of edges (each with a twist angle and a reference director) and a list
of bend–twist stencils (see :mod:`rotomorph.rod.stencils`). Frames follow Bergou et al. (2010):
reference directors are carried from the last accepted iterate to a trial configuration by
parallel transport in time, and the reference twist of each stencil is re-measured and unwrapped
to stay continuous with its previous value.

Global degrees of freedom are interleaved per node (``pos_dof[n]`` .. ``+2``) with one twist
angle per edge (``theta_dof[j]``); see :func:`rotomorph.rod.stencils.dof_layout`.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from rotomorph.rod.kernels import (
    _cross,
    _dot,
    _row,
    bend_measures,
    bend_twist_energy,
    bend_twist_stencil,
    stretch_edge,
    stretch_energy,
)

_CACHE = True


@njit(cache=_CACHE)
def _transport(u, ta, tb):
    """Parallel transport of 3-tuple ``u`` from unit ``ta`` to unit ``tb`` (tuples)."""
    b = _cross(ta, tb)
    s = np.sqrt(_dot(b, b))
    if s < 1e-14:
        return u
    b = (b[0] / s, b[1] / s, b[2] / s)
    n1 = _cross(ta, b)
    n2 = _cross(tb, b)
    ua = _dot(u, ta)
    un = _dot(u, n1)
    ub = _dot(u, b)
    return (
        ua * tb[0] + un * n2[0] + ub * b[0],
        ua * tb[1] + un * n2[1] + ub * b[1],
        ua * tb[2] + un * n2[2] + ub * b[2],
    )


@njit(cache=_CACHE)
def transport_frames(pos, edges, t_old, d1_old, t_new, d1_new):
    """Tangents of ``pos`` and reference directors transported in time from ``(t_old, d1_old)``."""
    for j in range(edges.shape[0]):
        a = edges[j, 0]
        c = edges[j, 1]
        v = (pos[c, 0] - pos[a, 0], pos[c, 1] - pos[a, 1], pos[c, 2] - pos[a, 2])
        ln = np.sqrt(_dot(v, v))
        tb = (v[0] / ln, v[1] / ln, v[2] / ln)
        d = _transport(_row(d1_old, j), _row(t_old, j), tb)
        # re-orthonormalise against round-off drift
        p = _dot(d, tb)
        d = (d[0] - p * tb[0], d[1] - p * tb[1], d[2] - p * tb[2])
        nn = np.sqrt(_dot(d, d))
        for k in range(3):
            t_new[j, k] = tb[k]
            d1_new[j, k] = d[k] / nn


@njit(cache=_CACHE)
def material_frames(t, d1, theta, m1, m2):
    """Material directors ``m1 = cos(theta) d1 + sin(theta) d2`` and ``m2 = t x m1``."""
    for j in range(t.shape[0]):
        d = _row(d1, j)
        d2 = _cross(_row(t, j), d)
        c = np.cos(theta[j])
        s = np.sin(theta[j])
        for k in range(3):
            m1[j, k] = c * d[k] + s * d2[k]
            m2[j, k] = -s * d[k] + c * d2[k]


@njit(cache=_CACHE)
def reference_twist(st_edges, st_signs, t, d1, mref_old, mref_new):
    """Reference twist of every stencil, unwrapped to within pi of ``mref_old`` (rad).

    ``st_edges`` (S, 2) = (edge_e, edge_f) and ``st_signs`` (S, 2) packed as in
    :func:`evaluate_network`, so the Python callers and the compiled one share one compiled
    specialisation (column slices would be non-contiguous arrays, a second one).
    """
    for s in range(st_edges.shape[0]):
        ea = st_edges[s, 0]
        fb = st_edges[s, 1]
        se = st_signs[s, 0]
        sf = st_signs[s, 1]
        te = (se * t[ea, 0], se * t[ea, 1], se * t[ea, 2])
        tf = (sf * t[fb, 0], sf * t[fb, 1], sf * t[fb, 2])
        pu = _transport(_row(d1, ea), te, tf)
        v = _row(d1, fb)
        ang = np.arctan2(_dot(_cross(pu, v), tf), _dot(pu, v))
        old = mref_old[s]
        ang += 2.0 * np.pi * np.round((old - ang) / (2.0 * np.pi))
        mref_new[s] = ang


@njit(cache=_CACHE)
def assemble(
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
    st_B1,
    st_B2,
    st_C,
    st_voronoi,
    st_k1bar,
    st_k2bar,
    st_taubar,
    edges,
    axial,
    rest,
    pos_dof,
    theta_dof,
    ndof,
    need_grad,
    need_hess,
    grad_out,
    st_hess,
    ed_hess,
):
    """Total elastic energy (N mm); gradient into ``grad_out`` (ndof,); local Hessians.

    ``st_hess`` (S, 11, 11) receives each stencil's Hessian in its *global* sign convention
    (twist-angle rows/columns multiplied by the stencil's edge signs); ``ed_hess`` (E, 6, 6)
    each edge's stretching Hessian.
    """
    D = np.empty((3, 3, 3))
    gk = np.empty((3, 11))
    g = np.empty(11)
    H = np.empty((11, 11))
    g6 = np.empty(6)
    energy = 0.0
    if need_grad:
        for k in range(ndof):
            grad_out[k] = 0.0
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
        en, _, _ = bend_twist_stencil(
            _row(pos, n0),
            _row(pos, n1),
            _row(pos, n2),
            _row(m1, ea),
            m2e,
            _row(m1, fb),
            m2f,
            tw,
            st_B1[s],
            st_B2[s],
            st_C[s],
            st_voronoi[s],
            st_k1bar[s],
            st_k2bar[s],
            st_taubar[s],
            g,
            H,
            need_grad,
            need_hess,
            D,
            gk,
        )
        energy += en
        if need_grad:
            for k in range(3):
                grad_out[pos_dof[n0] + k] += g[k]
                grad_out[pos_dof[n1] + k] += g[4 + k]
                grad_out[pos_dof[n2] + k] += g[8 + k]
            grad_out[theta_dof[ea]] += se * g[3]
            grad_out[theta_dof[fb]] += sf * g[7]
        if need_hess:
            for i in range(11):
                for j in range(11):
                    st_hess[s, i, j] = H[i, j]
            # twist-angle rows and columns in the edges' own orientation
            for k in range(11):
                st_hess[s, 3, k] *= se
                st_hess[s, k, 3] *= se
                st_hess[s, 7, k] *= sf
                st_hess[s, k, 7] *= sf
    H6 = np.empty((6, 6))
    for j in range(edges.shape[0]):
        a = edges[j, 0]
        b = edges[j, 1]
        energy += stretch_edge(
            _row(pos, a), _row(pos, b), axial[j], rest[j], g6, H6, need_grad, need_hess
        )
        if need_grad:
            for k in range(3):
                grad_out[pos_dof[a] + k] += g6[k]
                grad_out[pos_dof[b] + k] += g6[3 + k]
        if need_hess:
            for p in range(6):
                for q in range(6):
                    ed_hess[j, p, q] = H6[p, q]
    return energy


@njit(cache=_CACHE)
def scatter_banded(st_hess, st_dofs, ed_hess, ed_dofs, reduced, u, ab):
    """Add local Hessians into upper banded storage ``ab[u + i - j, j]`` (reduced DOFs)."""
    for r in range(ab.shape[0]):
        for c in range(ab.shape[1]):
            ab[r, c] = 0.0
    for s in range(st_hess.shape[0]):
        for a in range(11):
            i = reduced[st_dofs[s, a]]
            if i < 0:
                continue
            for b in range(11):
                j = reduced[st_dofs[s, b]]
                if j < i:
                    continue
                ab[u + i - j, j] += st_hess[s, a, b]
    for e in range(ed_hess.shape[0]):
        for a in range(6):
            i = reduced[ed_dofs[e, a]]
            if i < 0:
                continue
            for b in range(6):
                j = reduced[ed_dofs[e, b]]
                if j < i:
                    continue
                ab[u + i - j, j] += ed_hess[e, a, b]


@njit(cache=_CACHE)
def scatter_sparse(st_hess, st_slot, ed_hess, ed_slot, data):
    """Add local Hessians into CSC ``data`` at precomputed slots (-1 = fixed DOF)."""
    for k in range(data.shape[0]):
        data[k] = 0.0
    for s in range(st_hess.shape[0]):
        for a in range(11):
            for b in range(11):
                p = st_slot[s, a, b]
                if p >= 0:
                    data[p] += st_hess[s, a, b]
    for e in range(ed_hess.shape[0]):
        for a in range(6):
            for b in range(6):
                p = ed_slot[e, a, b]
                if p >= 0:
                    data[p] += ed_hess[e, a, b]


@njit(cache=_CACHE)
def evaluate_network(
    pos,
    theta,
    t_base,
    d1_base,
    mref_base,
    t,
    d1,
    m1,
    m2,
    mref,
    edges,
    st_nodes,
    st_edges,
    st_signs,
    st_params,
    ed_params,
    pos_dof,
    theta_dof,
    ndof,
    need_grad,
    need_hess,
    grad_out,
    st_hess,
    ed_hess,
):
    """Frames transported from the base, reference twists, then :func:`assemble`.

    Packed parameters: ``st_edges`` (S, 2) = (edge_e, edge_f); ``st_signs`` (S, 2);
    ``st_params`` (S, 7) = (B1, B2, C, voronoi, kappa1_bar, kappa2_bar, tau_bar) integrated;
    ``ed_params`` (E, 2) = (EA, rest length). One compiled call per evaluation keeps the
    per-call overhead of many array arguments out of the Newton loop. Without gradient and
    Hessian (a line-search trial) the energy comes from :func:`network_energy`.
    """
    if not (need_grad or need_hess):
        return network_energy(
            pos,
            theta,
            t_base,
            d1_base,
            mref_base,
            t,
            d1,
            m1,
            m2,
            mref,
            edges,
            st_nodes,
            st_edges,
            st_signs,
            st_params,
            ed_params,
        )
    transport_frames(pos, edges, t_base, d1_base, t, d1)
    reference_twist(st_edges, st_signs, t, d1, mref_base, mref)
    material_frames(t, d1, theta, m1, m2)
    return assemble(
        pos,
        theta,
        m1,
        m2,
        mref,
        st_nodes,
        st_edges[:, 0],
        st_edges[:, 1],
        st_signs[:, 0],
        st_signs[:, 1],
        st_params[:, 0],
        st_params[:, 1],
        st_params[:, 2],
        st_params[:, 3],
        st_params[:, 4],
        st_params[:, 5],
        st_params[:, 6],
        edges,
        ed_params[:, 0],
        ed_params[:, 1],
        pos_dof,
        theta_dof,
        ndof,
        need_grad,
        need_hess,
        grad_out,
        st_hess,
        ed_hess,
    )


@njit(cache=_CACHE)
def network_energy(
    pos,
    theta,
    t_base,
    d1_base,
    mref_base,
    t,
    d1,
    m1,
    m2,
    mref,
    edges,
    st_nodes,
    st_edges,
    st_signs,
    st_params,
    ed_params,
):
    """The energy of :func:`evaluate_network` alone (N mm), with the same frames ``t, d1, m1,
    m2`` and reference twists ``mref``: no derivative work, no per-stencil work buffers.

    Every quantity comes from the same expressions, and the energies are summed in the same
    order (stencils, then edges), as in :func:`assemble`: the two agree to the last bit.
    """
    transport_frames(pos, edges, t_base, d1_base, t, d1)
    reference_twist(st_edges, st_signs, t, d1, mref_base, mref)
    material_frames(t, d1, theta, m1, m2)
    energy = 0.0
    for s in range(st_nodes.shape[0]):
        ea = st_edges[s, 0]
        fb = st_edges[s, 1]
        se = st_signs[s, 0]
        sf = st_signs[s, 1]
        m2e = (se * m2[ea, 0], se * m2[ea, 1], se * m2[ea, 2])
        m2f = (sf * m2[fb, 0], sf * m2[fb, 1], sf * m2[fb, 2])
        kappa1, kappa2 = bend_measures(
            _row(pos, st_nodes[s, 0]),
            _row(pos, st_nodes[s, 1]),
            _row(pos, st_nodes[s, 2]),
            _row(m1, ea),
            m2e,
            _row(m1, fb),
            m2f,
        )[6:]
        tw = sf * theta[fb] - se * theta[ea] + mref[s]
        energy += bend_twist_energy(
            kappa1,
            kappa2,
            tw,
            st_params[s, 0],
            st_params[s, 1],
            st_params[s, 2],
            st_params[s, 3],
            st_params[s, 4],
            st_params[s, 5],
            st_params[s, 6],
        )[0]
    for j in range(edges.shape[0]):
        a = edges[j, 0]
        b = edges[j, 1]
        e0 = pos[b, 0] - pos[a, 0]
        e1 = pos[b, 1] - pos[a, 1]
        e2 = pos[b, 2] - pos[a, 2]
        length = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        energy += stretch_energy(length, ed_params[j, 0], ed_params[j, 1])[0]
    return energy
