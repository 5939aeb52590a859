"""Moving a rod network along a Newton step by rotating its edges (a retraction).

A chord step ``x + alpha dx`` stretches every edge it turns (a rotation by angle ``phi`` of an
edge of length ``l`` lengthens it by ``l phi^2 / 2``), which the stiff stretching energy punishes
and the line search answers with short steps. Instead, each edge is rotated by the rotation the
step implies (axis and angle from the perpendicular part of ``de``) and stretched by its axial
part; the nodes are then recomposed from the edges: exactly, by accumulation from a root, when
the network is a tree with at most one supported node (a single filament), else by least
squares on the graph with supported nodes held fixed (or the first node moved linearly for a
free body). To first order in ``alpha`` this is the chord step, so the Newton direction and the
Armijo test are unchanged (a retraction in the sense of Absil, Mahony & Sepulchre,
*Optimization Algorithms on Matrix Manifolds*, 2008, § 4.1).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from numba import njit

from rotomorph._typing import FloatArray, IntArray


@njit(cache=True)
def _edge_targets(x, dx, alpha, edges, out):
    """Rotated and stretched edge vectors ``(E, 3)`` for step ``alpha dx``."""
    for j in range(edges.shape[0]):
        a = edges[j, 0]
        b = edges[j, 1]
        e0 = x[b, 0] - x[a, 0]
        e1 = x[b, 1] - x[a, 1]
        e2 = x[b, 2] - x[a, 2]
        d0 = dx[b, 0] - dx[a, 0]
        d1 = dx[b, 1] - dx[a, 1]
        d2 = dx[b, 2] - dx[a, 2]
        ln = np.sqrt(e0 * e0 + e1 * e1 + e2 * e2)
        t0, t1, t2 = e0 / ln, e1 / ln, e2 / ln
        axial = (t0 * d0 + t1 * d1 + t2 * d2) / ln
        # rotation vector w = alpha * t x de / |e|
        w0 = alpha * (t1 * d2 - t2 * d1) / ln
        w1 = alpha * (t2 * d0 - t0 * d2) / ln
        w2 = alpha * (t0 * d1 - t1 * d0) / ln
        ang = np.sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        scale = ln * (1.0 + alpha * axial)
        if ang > 0.0:
            k0, k1, k2 = w0 / ang, w1 / ang, w2 / ang
            c = np.cos(ang)
            s = np.sin(ang)
            # Rodrigues for k perpendicular to t: t c + (k x t) s
            out[j, 0] = scale * (c * t0 + s * (k1 * t2 - k2 * t1))
            out[j, 1] = scale * (c * t1 + s * (k2 * t0 - k0 * t2))
            out[j, 2] = scale * (c * t2 + s * (k0 * t1 - k1 * t0))
        else:
            out[j, 0] = scale * t0
            out[j, 1] = scale * t1
            out[j, 2] = scale * t2


@njit(cache=True)
def _accumulate_tree(x, dx, alpha, root, move_root, order, parent, parent_edge, sign, target, out):
    for k in range(3):
        out[root, k] = x[root, k] + (alpha * dx[root, k] if move_root else 0.0)
    for i in range(order.shape[0]):
        n = order[i]
        p = parent[n]
        j = parent_edge[n]
        for k in range(3):
            out[n, k] = out[p, k] + sign[n] * target[j, k]


class EdgeRotationRetraction:
    """Retraction for node positions of a network with ``edges`` and fixed nodes ``fixed``."""

    def __init__(self, edges: IntArray, n_nodes: int, fixed_nodes: IntArray) -> None:
        self.edges = np.ascontiguousarray(edges, dtype=np.int64)
        self._target = np.empty((len(edges), 3))
        fixed = np.zeros(n_nodes, dtype=bool)
        fixed[fixed_nodes] = True
        self.anchor_first = not fixed.any()
        is_tree = len(edges) == n_nodes - 1 and fixed.sum() <= 1
        # (root, order, parent, parent_edge, sign) of a spanning tree, or None
        self._tree: tuple[int, IntArray, IntArray, IntArray, FloatArray] | None
        if is_tree:
            root = int(np.flatnonzero(fixed)[0]) if fixed.any() else 0
            tree = _bfs_tree(self.edges, n_nodes, root)
            if tree is not None:
                self._tree = (root, *tree)
                return
        self._tree = None
        if self.anchor_first:
            fixed[0] = True
        self.fixed = np.flatnonzero(fixed)
        self.free = np.flatnonzero(~fixed)
        e = len(edges)
        B = sp.csr_matrix(
            (
                np.r_[-np.ones(e), np.ones(e)],
                (np.r_[np.arange(e), np.arange(e)], np.r_[edges[:, 0], edges[:, 1]]),
            ),
            shape=(e, n_nodes),
        )
        Bd = B[:, self.fixed].tocsc()
        Bf = B[:, self.free].tocsc()
        BfT = Bf.T.tocsr()
        self._lu = spla.splu((BfT @ Bf).tocsc()) if len(self.free) else None
        # the sparse products of the right-hand side, compiled (see _least_squares_rhs)
        self._Bd = (Bd.indptr.astype(np.int64), Bd.indices.astype(np.int64), Bd.data)
        self._BfT = (BfT.indptr.astype(np.int64), BfT.indices.astype(np.int64), BfT.data)
        self._residual = np.empty((e, 3))
        self._rhs = np.empty((len(self.free), 3))

    def __call__(self, x: FloatArray, dx: FloatArray, alpha: float) -> FloatArray:
        """Node positions ``(N, 3)`` reached from ``x`` along ``alpha dx`` (both ``(N, 3)``)."""
        _edge_targets(x, dx, alpha, self.edges, self._target)
        out = np.empty_like(x)
        if self._tree is not None:
            root, order, parent, parent_edge, sign = self._tree
            _accumulate_tree(
                x,
                dx,
                alpha,
                root,
                self.anchor_first,
                order,
                parent,
                parent_edge,
                sign,
                self._target,
                out,
            )
            return out
        _least_squares_rhs(
            x,
            dx,
            alpha,
            self.anchor_first,
            self.fixed,
            *self._Bd,
            *self._BfT,
            self._target,
            self._residual,
            out,
            self._rhs,
        )
        if self._lu is not None:
            _set_rows(out, self.free, self._lu.solve(self._rhs))
        return out


@njit(cache=True)
def _least_squares_rhs(
    x,
    dx,
    alpha,
    move_fixed,
    fixed,
    bd_ptr,
    bd_idx,
    bd_val,
    bt_ptr,
    bt_idx,
    bt_val,
    target,
    residual,
    out,
    rhs,
):  # pragma: no cover - compiled
    """Fixed nodes of ``out`` and the right-hand side ``Bf^T (target - Bd xd)`` of the least
    squares, ``Bd`` (CSC) and ``Bf^T`` (CSR) given by their arrays.

    The products accumulate in SciPy's order (``csc_matvecs``, ``csr_matvecs``), so the nodes
    are the same to the last bit as with its sparse matrices, without their per-call overhead.
    """
    for i in range(fixed.shape[0]):
        n = fixed[i]
        for k in range(3):
            out[n, k] = x[n, k] + (alpha * dx[n, k] if move_fixed else 0.0)
    for r in range(residual.shape[0]):
        for k in range(3):
            residual[r, k] = 0.0
    for c in range(fixed.shape[0]):
        n = fixed[c]
        for p in range(bd_ptr[c], bd_ptr[c + 1]):
            r = bd_idx[p]
            for k in range(3):
                residual[r, k] += bd_val[p] * out[n, k]
    for r in range(residual.shape[0]):
        for k in range(3):
            residual[r, k] = target[r, k] - residual[r, k]
    for i in range(rhs.shape[0]):
        for k in range(3):
            rhs[i, k] = 0.0
        for p in range(bt_ptr[i], bt_ptr[i + 1]):
            r = bt_idx[p]
            for k in range(3):
                rhs[i, k] += bt_val[p] * residual[r, k]


@njit(cache=True)
def _set_rows(out, rows, values):  # pragma: no cover - compiled
    """``out[rows] = values`` for ``(N, 3)`` arrays."""
    for i in range(rows.shape[0]):
        for k in range(3):
            out[rows[i], k] = values[i, k]


@njit(cache=True)
def split_step(u_base, free, q, d, pos_dof, u, du, x, dx):  # pragma: no cover - compiled
    """Layout vectors ``u`` (``u_base`` with ``q`` on the free DOFs) and ``du`` (``d`` there,
    0 elsewhere) and their node positions ``x``, ``dx`` (N, 3)."""
    for i in range(u.shape[0]):
        u[i] = u_base[i]
        du[i] = 0.0
    for i in range(free.shape[0]):
        u[free[i]] = q[i]
        du[free[i]] = d[i]
    for n in range(pos_dof.shape[0]):
        for k in range(3):
            x[n, k] = u[pos_dof[n] + k]
            dx[n, k] = du[pos_dof[n] + k]


@njit(cache=True)
def join_step(u, du, alpha, x, pos_dof, theta_dof, free, out):  # pragma: no cover - compiled
    """Free DOFs ``out`` of the layout vector ``u`` with node positions ``x`` and twist angles
    moved by ``alpha du``."""
    for n in range(pos_dof.shape[0]):
        for k in range(3):
            u[pos_dof[n] + k] = x[n, k]
    for j in range(theta_dof.shape[0]):
        u[theta_dof[j]] += alpha * du[theta_dof[j]]
    for i in range(free.shape[0]):
        out[i] = u[free[i]]


def _bfs_tree(edges: IntArray, n: int, root: int):  # type: ignore[no-untyped-def]
    """Breadth-first order, parents, parent edges and signs; None if not connected."""
    e = len(edges)
    ends = np.concatenate([edges[:, 0], edges[:, 1]])
    other = np.concatenate([edges[:, 1], edges[:, 0]])
    sign = np.concatenate([np.ones(e), -np.ones(e)])
    eid = np.concatenate([np.arange(e), np.arange(e)])
    order = np.argsort(ends, kind="stable")
    indptr = np.concatenate([[0], np.cumsum(np.bincount(ends, minlength=n))])
    out = _bfs(indptr, other[order], eid[order], sign[order], n, root)
    if out[0].shape[0] != n - 1:
        return None
    return out


@njit(cache=True)
def _bfs(indptr, nbr, eid, sgn, n, root):  # pragma: no cover - compiled
    parent = -np.ones(n, dtype=np.int64)
    parent_edge = -np.ones(n, dtype=np.int64)
    sign = np.zeros(n)
    seen = np.zeros(n, dtype=np.bool_)
    order = np.empty(n - 1 if n > 0 else 0, dtype=np.int64)
    queue = np.empty(n, dtype=np.int64)
    queue[0] = root
    seen[root] = True
    head, tail, count = 0, 1, 0
    while head < tail:
        p = queue[head]
        head += 1
        for k in range(indptr[p], indptr[p + 1]):
            c = nbr[k]
            if not seen[c]:
                seen[c] = True
                parent[c] = p
                parent_edge[c] = eid[k]
                sign[c] = sgn[k]
                if count < order.shape[0]:
                    order[count] = c
                count += 1
                queue[tail] = c
                tail += 1
    return order[: min(count, order.shape[0])], parent, parent_edge, sign


@njit(cache=True)
def max_edge_rotation(x, dx, edges):  # pragma: no cover - compiled
    """Largest rotation angle (rad, linearised) that the step ``dx`` gives an edge."""
    worst = 0.0
    for j in range(edges.shape[0]):
        a = edges[j, 0]
        b = edges[j, 1]
        e0, e1, e2 = x[b, 0] - x[a, 0], x[b, 1] - x[a, 1], x[b, 2] - x[a, 2]
        d0, d1, d2 = dx[b, 0] - dx[a, 0], dx[b, 1] - dx[a, 1], dx[b, 2] - dx[a, 2]
        ln2 = e0 * e0 + e1 * e1 + e2 * e2
        p = (d0 * e0 + d1 * e1 + d2 * e2) / ln2
        q0, q1, q2 = d0 - p * e0, d1 - p * e1, d2 - p * e2
        worst = max(worst, (q0 * q0 + q1 * q1 + q2 * q2) / ln2)
    return np.sqrt(worst)


def remove_rigid_motion(x, dx, m, t, dtheta, mtheta):
    """Subtract from ``(dx, dtheta)`` its M-orthogonal projection on rigid motions (in place).

    A small rigid rotation ``omega`` moves node ``i`` by ``omega x r_i`` *and* turns each edge's
    material frame about its tangent by ``omega . t_j`` beyond parallel transport, so the twist
    angles change by ``omega . t_j``. Translations (no twist part) and rotations about the
    ``m``-weighted centroid are M-orthogonal, so the projection is a translation plus the
    rotation solving ``G omega = b`` with
    ``G = sum m (|r|^2 I - r r^T) + sum m_theta t t^T`` and
    ``b = sum m r x dx + sum m_theta dtheta t``.

    The sums and the update are compiled; the 3 x 3 least-squares solve (minimum-norm where a
    straight rod leaves the rotation about its axis free) is NumPy's, which keeps LAPACK's
    compiled bindings out of the kernel (a quarter of the first-run compile time).
    """
    c, tr, G, b = _rigid_moments(x, dx, m, t, dtheta, mtheta)
    omega = np.linalg.lstsq(G, b, rcond=-1)[0]
    _subtract_rigid(x, dx, t, dtheta, c, tr, omega)


@njit(cache=True)
def _rigid_moments(x, dx, m, t, dtheta, mtheta):  # pragma: no cover - compiled
    """Centroid, mean displacement, ``G`` and ``b`` of :func:`remove_rigid_motion`."""
    n = x.shape[0]
    mt = 0.0
    c = np.zeros(3)
    tr = np.zeros(3)
    for i in range(n):
        mt += m[i]
        for k in range(3):
            c[k] += m[i] * x[i, k]
            tr[k] += m[i] * dx[i, k]
    for k in range(3):
        c[k] /= mt
        tr[k] /= mt
    G = np.zeros((3, 3))
    b = np.zeros(3)
    for i in range(n):
        r0, r1, r2 = x[i, 0] - c[0], x[i, 1] - c[1], x[i, 2] - c[2]
        v0, v1, v2 = dx[i, 0] - tr[0], dx[i, 1] - tr[1], dx[i, 2] - tr[2]
        rr = r0 * r0 + r1 * r1 + r2 * r2
        r = (r0, r1, r2)
        for a in range(3):
            G[a, a] += m[i] * rr
            for k in range(3):
                G[a, k] -= m[i] * r[a] * r[k]
        b[0] += m[i] * (r1 * v2 - r2 * v1)
        b[1] += m[i] * (r2 * v0 - r0 * v2)
        b[2] += m[i] * (r0 * v1 - r1 * v0)
    for j in range(t.shape[0]):
        for a in range(3):
            b[a] += mtheta[j] * dtheta[j] * t[j, a]
            for k in range(3):
                G[a, k] += mtheta[j] * t[j, a] * t[j, k]
    return c, tr, G, b


@njit(cache=True)
def _subtract_rigid(x, dx, t, dtheta, c, tr, omega):  # pragma: no cover - compiled
    """``(dx, dtheta) -= translation tr + rotation omega about c`` (in place)."""
    for i in range(x.shape[0]):
        r0, r1, r2 = x[i, 0] - c[0], x[i, 1] - c[1], x[i, 2] - c[2]
        dx[i, 0] -= tr[0] + omega[1] * r2 - omega[2] * r1
        dx[i, 1] -= tr[1] + omega[2] * r0 - omega[0] * r2
        dx[i, 2] -= tr[2] + omega[0] * r1 - omega[1] * r0
    for j in range(t.shape[0]):
        dtheta[j] -= omega[0] * t[j, 0] + omega[1] * t[j, 1] + omega[2] * t[j, 2]
