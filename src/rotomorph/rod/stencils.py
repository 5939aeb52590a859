"""Bend–twist stencils and degree-of-freedom layout of a rod network.

A stencil couples an *incoming* edge ``e`` (pointing into the node) and an *outgoing* edge
``f`` (pointing away from it) at one node. Stored edges keep their own orientation; a sign
``+1`` means the stored edge already points the stencil's way, ``-1`` that the stencil sees it
reversed (tangent and ``m2`` flipped, twist angle negated, ``m1`` unchanged).

* An ordinary rod vertex (a non-branch node of degree two) gives one stencil with the rod's
  anisotropic bending stiffnesses.
* A branch node of degree ``k`` gives one stencil for each of the ``k(k-1)/2`` unique pairs of
  incident edges (the paper's junction rule, its ref. 70; the same pair rule as disMech's
  joints), each with isotropic stiffness, its own reference frames and reference twist.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.design.network import Network
from rotomorph.errors import InvalidDesignError


@dataclass(frozen=True, eq=False)
class Stencils:
    """Stencil topology of a network (arrays of length S).

    Attributes
    ----------
    nodes
        ``(S, 3)`` node indices ``[x0, x1, x2]``: far end of ``e``, shared node, far end of ``f``.
    edge_e, edge_f
        ``(S,)`` indices of the incoming and outgoing edges.
    sign_e, sign_f
        ``(S,)`` orientation signs (+1 or -1, as floats).
    junction
        ``(S,)`` True for branch-node pair stencils (isotropic stiffness).
    """

    nodes: IntArray
    edge_e: IntArray
    edge_f: IntArray
    sign_e: FloatArray
    sign_f: FloatArray
    junction: BoolArray

    @property
    def count(self) -> int:
        """Number of stencils S."""
        return len(self.edge_e)


_STENCILS: weakref.WeakKeyDictionary[Network, Stencils] = weakref.WeakKeyDictionary()
_LAYOUTS: weakref.WeakKeyDictionary[Network, DofLayout] = weakref.WeakKeyDictionary()


def build_stencils(network: Network) -> Stencils:
    """Stencils of ``network``: one per rod vertex, one per edge pair at each branch node.

    Cached per (immutable) network, so models that differ only in their natural fields (a
    heating ramp) share the topology work.

    Raises
    ------
    InvalidDesignError
        If a non-branch node has more than two edges, or the network has no stencil at all
        (a single segment cannot bend).
    """
    cached = _STENCILS.get(network)
    if cached is not None:
        return cached
    st = _build_stencils(network)
    _STENCILS[network] = st
    return st


def _build_stencils(network: Network) -> Stencils:
    edges = np.asarray(network.edges, dtype=np.int64)
    branch = np.asarray(network.branch, dtype=bool)
    # incidence grouped by node, each node's segments in index order
    node_of = edges.ravel()
    edge_of = np.repeat(np.arange(len(edges), dtype=np.int64), 2)
    order = np.lexsort((edge_of, node_of))
    node_of, edge_of = node_of[order], edge_of[order]
    degree = np.bincount(node_of, minlength=network.n_nodes)
    first = np.concatenate([[0], np.cumsum(degree)[:-1]])
    bad = np.flatnonzero(~branch & (degree > 2))
    if len(bad):
        raise InvalidDesignError(
            "Network.branch",
            f"node {int(bad[0])} joins {int(degree[bad[0]])} segments but is not flagged as a "
            "branch node",
        )
    # one pair per rod vertex, every pair (p < q, in segment order) at a branch node
    centre, seg_a, seg_b = [], [], []
    for k in np.unique(degree[degree >= 2]):
        nodes = np.flatnonzero(degree == k)
        inc = edge_of[first[nodes][:, None] + np.arange(k)]
        p, q = np.triu_indices(int(k), 1)
        centre.append(np.repeat(nodes, len(p)))
        seg_a.append(inc[:, p].ravel())
        seg_b.append(inc[:, q].ravel())
    if not centre:
        raise InvalidDesignError(
            "Network", "has no node joining two segments; a rod needs N >= 3 nodes"
        )
    by_node = np.argsort(np.concatenate(centre), kind="stable")
    n = np.concatenate(centre)[by_node]
    a = np.concatenate(seg_a)[by_node]
    b = np.concatenate(seg_b)[by_node]
    # a rod vertex lists a segment pointing into the node first: segments are listed by
    # index, so where a ring closes (node 0 of Network.ring: segment 0 leaves it, the last
    # segment enters it) the pair would otherwise be seen reversed on both sides; ordered, the
    # closing vertex is a vertex like any other, with the ring's orientation
    swap = ~branch[n] & (edges[a, 1] != n) & (edges[b, 1] == n)
    a, b = np.where(swap, b, a), np.where(swap, a, b)
    into_a = edges[a, 1] == n
    out_b = edges[b, 0] == n
    far_a = np.where(into_a, edges[a, 0], edges[a, 1])
    far_b = np.where(out_b, edges[b, 1], edges[b, 0])
    return Stencils(
        nodes=np.column_stack([far_a, n, far_b]),
        edge_e=a,
        edge_f=b,
        sign_e=np.where(into_a, 1.0, -1.0),
        sign_f=np.where(out_b, 1.0, -1.0),
        junction=branch[n].copy(),
    )


@dataclass(frozen=True, eq=False)
class DofLayout:
    """Interleaved global DOF numbering: each node's 3 coordinates, then the twist angles of
    the edges that start at it (a chain gets ``[x0, theta0, x1, theta1, ...]``, whose Hessian is
    banded with half-bandwidth 10)."""

    pos: IntArray
    theta: IntArray
    count: int

    def stencil_dofs(self, st: Stencils) -> IntArray:
        """``(S, 11)`` global DOFs in kernel order ``[x0, th_e, x1, th_f, x2]``."""
        p = self.pos[st.nodes]
        out = np.empty((st.count, 11), dtype=np.int64)
        for k in range(3):
            out[:, k] = p[:, 0] + k
            out[:, 4 + k] = p[:, 1] + k
            out[:, 8 + k] = p[:, 2] + k
        out[:, 3] = self.theta[st.edge_e]
        out[:, 7] = self.theta[st.edge_f]
        return out

    def edge_dofs(self, edges: IntArray) -> IntArray:
        """``(E, 6)`` global DOFs ``[x_a, x_b]`` of each edge's end nodes."""
        p = self.pos[edges]
        return np.concatenate([p[:, :1] + np.arange(3), p[:, 1:] + np.arange(3)], axis=1)


def dof_layout(network: Network) -> DofLayout:
    """Node-interleaved DOF layout of ``network`` (see :class:`DofLayout`); cached."""
    cached = _LAYOUTS.get(network)
    if cached is not None:
        return cached
    layout = _dof_layout(network)
    _LAYOUTS[network] = layout
    return layout


def _dof_layout(network: Network) -> DofLayout:
    starts = np.bincount(network.edges[:, 0], minlength=network.n_nodes)
    sizes = 3 + starts
    pos = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.int64)
    order = np.argsort(network.edges[:, 0], kind="stable")
    rank = np.empty(network.n_edges, dtype=np.int64)
    first = network.edges[order, 0]
    # rank of each edge among the edges starting at the same node
    group_start = np.searchsorted(first, first, side="left")
    rank[order] = np.arange(network.n_edges) - group_start
    theta = pos[network.edges[:, 0]] + 3 + rank
    return DofLayout(pos=pos, theta=theta.astype(np.int64), count=int(sizes.sum()))
