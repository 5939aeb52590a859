"""Which segment pairs of a network may touch: neighbours along the network graph may not.

Two segments whose centre lines are joined by a short path *along the network* (the same rod a
few segments on, or another filament across a printed junction) are not in contact when close:
they are one piece of material. The test is the graph distance, not the node index: the
shortest path along the network between their nearest end nodes (Dijkstra on the printed
segment lengths), excluded when shorter than ``reach``. A filament of radius ``r`` cannot bend
back onto itself within an arc of ``π r`` (a half turn at the tightest radius ``r`` its own
thickness allows), so the default reach is ``π (r_a + r_b) / 2``, never less than one segment.

Pairs closer than their contact distance plus the activation distance *as printed* are fused
(layers and crossings printed onto each other): excluded too, so the printed state is always an
admissible start.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.distance import pair_distances

__all__ = ["excluded_pairs", "graph_neighbour_pairs", "pair_keys"]

_CHUNK = 512  # source nodes per Dijkstra call (bounds memory to CHUNK x N floats)


def pair_keys(pairs: IntArray, n: int) -> IntArray:
    """Sorted int64 keys ``i * n + j`` (``i < j``) of segment pairs ``(P, 2)``."""
    p = np.sort(np.asarray(pairs, dtype=np.int64).reshape(-1, 2), axis=1)
    return np.unique(p[:, 0] * n + p[:, 1])


def graph_neighbour_pairs(nodes: FloatArray, edges: IntArray, reach: float) -> IntArray:
    """Segment pairs ``(P, 2)``, ``i < j``, whose nearest end nodes are joined by a network path
    shorter than ``reach`` (mm); pairs sharing a node are included (path length 0)."""
    n = len(nodes)
    length = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
    graph = sp.csr_matrix(
        (np.r_[length, length], (np.r_[edges[:, 0], edges[:, 1]], np.r_[edges[:, 1], edges[:, 0]])),
        shape=(n, n),
    )
    rows, cols = [], []
    for start in range(0, n, _CHUNK):
        src = np.arange(start, min(start + _CHUNK, n))
        dist = dijkstra(graph, directed=False, indices=src, limit=reach)
        r, c = np.nonzero(dist < reach)
        rows.append(src[r])
        cols.append(c)
    near = sp.csr_matrix(
        (np.ones(sum(len(r) for r in rows)), (np.concatenate(rows), np.concatenate(cols))),
        shape=(n, n),
    )
    inc = sp.csr_matrix(
        (np.ones(2 * len(edges)), (np.repeat(np.arange(len(edges)), 2), edges.ravel())),
        shape=(len(edges), n),
    )
    seg = (inc @ near @ inc.T).tocoo()
    keep = seg.row < seg.col
    return np.stack([seg.row[keep], seg.col[keep]], axis=1).astype(np.int64)


def excluded_pairs(
    nodes: FloatArray,
    edges: IntArray,
    radius: FloatArray,
    activation: float,
    reach: float | None = None,
) -> IntArray:
    """Sorted keys (:func:`pair_keys`) of segment pairs that may not touch.

    Parameters
    ----------
    nodes, edges
        The printed network (mm).
    radius
        Filament radius per segment (mm).
    activation
        Activation distance of the barrier (mm).
    reach
        Graph distance below which pairs are neighbours (mm); default ``π max(r_a + r_b) / 2``
        and at least the longest segment.
    """
    edges = np.asarray(edges, dtype=np.int64)
    length = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
    if reach is None:
        reach = max(0.5 * np.pi * 2.0 * float(radius.max()), float(length.max()))
    near = graph_neighbour_pairs(nodes, edges, reach)
    # fused as printed: closer than contact distance + activation
    mid = 0.5 * (nodes[edges[:, 0]] + nodes[edges[:, 1]])
    cand = (
        cKDTree(mid)
        .query_pairs(
            2.0 * float(radius.max()) + activation + float(length.max()), output_type="ndarray"
        )
        .reshape(-1, 2)
    )
    fused = np.zeros((0, 2), dtype=np.int64)
    if len(cand):
        quads = np.ascontiguousarray(np.concatenate([edges[cand[:, 0]], edges[cand[:, 1]]], 1))
        # a writable copy: a read-only array is another type to numba (a second compilation)
        d = pair_distances(np.array(nodes, dtype=float), quads)
        limit = radius[cand[:, 0]] + radius[cand[:, 1]] + activation
        fused = cand[d < limit]
    return pair_keys(np.concatenate([near, fused]), len(edges))
