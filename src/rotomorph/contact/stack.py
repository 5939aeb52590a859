r"""The printed stack as contact geometry: one capsule per layer, and which layer pairs overlap.

A lattice printed in N layers is one rod per edge whose cross-section is the fused stack
(:mod:`rotomorph.materials.stack`). Its layers are round filaments of radius r whose centre
lines lie at offsets :math:`o_k` along the segment's material director m1 (the printed sheet
normal), :math:`o_k = (k - (N-1)/2)\,h` for layer height h. Layer k of segment e is the capsule
of radius r around

.. math::  P^{e,k}_0 = x_{a} + o_k\, m_1^e, \qquad P^{e,k}_1 = x_{b} + o_k\, m_1^e

(segment e from node a to node b). Virtual segment ``v = k E + e`` holds layer k of segment
e, its end points are the virtual points ``2 v`` and ``2 v + 1`` (:func:`layer_points`).

Which layer pairs may touch (:func:`stack_exclusion`): layers of one segment and of segments
joined by a short path along the network are one piece of material. A rod of radius r bends
back onto itself only after half a turn at the tightest radius its thickness allows; a layer at
offset o of a stack that bends toward its director runs at radius ρ − o when the centre line
runs at ρ, so the layer reaches its own tightest radius r at ρ = r + ‖o‖. Layer pair (k, l) of
two segments is therefore excluded when their graph distance (shortest path along the printed
network between their nearest nodes) is below

.. math::  \text{reach}_{kl} = \text{reach} + \tfrac{\pi}{2}\,(|o_k| + |o_l|),

``reach`` the single-filament value (:mod:`rotomorph.contact.exclusion`, default
``π (r_a + r_b)/2``); for one layer at offset 0 this is that module's rule. Layer pairs closer
than their contact distance plus the activation distance as printed are fused (excluded).

:func:`stack_overlaps` lists the layer pairs that interpenetrate in a configuration: the check
of admissibility (every layer of every segment outside every other one it may touch).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import dijkstra
from scipy.spatial import cKDTree

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.distance import pair_distances
from rotomorph.contact.exclusion import pair_keys
from rotomorph.errors import InvalidParameterError

__all__ = [
    "Stack",
    "StackOverlaps",
    "layer_edges",
    "layer_points",
    "segment_graph_distances",
    "stack_exclusion",
    "stack_overlaps",
]

_CHUNK = 512  # source nodes per Dijkstra call


@dataclass(frozen=True)
class Stack:
    """Layer centre lines of a printed stack relative to the rod's centre line.

    Parameters
    ----------
    offsets
        Offset of each layer's centre line along the segment's material director m1 (mm),
        bottom (first printed) layer first. ``(0.0,)``: one filament on the centre line.
    """

    offsets: tuple[float, ...] = (0.0,)

    def __post_init__(self) -> None:
        o = tuple(float(v) for v in np.asarray(self.offsets, dtype=float).reshape(-1))
        if not o or not all(np.isfinite(o)):
            raise InvalidParameterError("Stack.offsets", "must be one or more finite mm values")
        if any(b <= a for a, b in itertools.pairwise(o)):
            raise InvalidParameterError("Stack.offsets", f"must increase (bottom first); got {o}")
        object.__setattr__(self, "offsets", o)

    @classmethod
    def layered(cls, layers: int, layer_height: float) -> Stack:
        """``layers`` layers ``layer_height`` (mm) apart, centred on the rod's centre line."""
        if int(layers) != layers or layers < 1:
            raise InvalidParameterError("layers", f"must be an integer >= 1; got {layers}")
        if not (np.isfinite(layer_height) and layer_height > 0):
            raise InvalidParameterError("layer_height", f"must be > 0 mm; got {layer_height}")
        k = np.arange(int(layers), dtype=float)
        return cls(tuple(float(v) for v in (k - 0.5 * (layers - 1)) * float(layer_height)))

    @property
    def count(self) -> int:
        """Number of layers N."""
        return len(self.offsets)

    @property
    def is_single(self) -> bool:
        """One layer on the centre line (the plain filament)."""
        return self.offsets == (0.0,)

    @property
    def extent(self) -> float:
        """Largest ``|o_k|`` (mm): how far the outermost layer's centre line lies off the rod's."""
        return float(np.max(np.abs(self.offsets)))

    def layer_of(self, virtual: IntArray, n_edges: int) -> tuple[IntArray, IntArray]:
        """(layer, segment) of virtual segments ``v = k E + e``."""
        v = np.asarray(virtual, dtype=np.int64)
        return v // n_edges, v % n_edges


def layer_points(
    positions: FloatArray, edges: IntArray, directors: FloatArray, offsets: tuple[float, ...]
) -> FloatArray:
    """End points ``(2 N E, 3)`` (mm) of every layer of every segment (module docstring).

    Parameters
    ----------
    positions
        Node positions ``(n, 3)`` (mm).
    edges
        Segments ``(E, 2)``.
    directors
        Material director m1 of every segment ``(E, 3)`` (unit).
    offsets
        Layer offsets along m1 (mm), :attr:`Stack.offsets`.
    """
    x = np.asarray(positions, dtype=float)
    m1 = np.asarray(directors, dtype=float)
    o = np.asarray(offsets, dtype=float)
    shift = o[:, None, None] * m1[None, :, :]  # (N, E, 3)
    out = np.empty((len(o), len(edges), 2, 3))
    out[:, :, 0] = x[edges[:, 0]][None] + shift
    out[:, :, 1] = x[edges[:, 1]][None] + shift
    return out.reshape(-1, 3)


def layer_edges(n_edges: int, layers: int) -> IntArray:
    """Virtual segments ``(N E, 2)``: segment ``v`` joins virtual points ``2 v`` and ``2 v + 1``."""
    v = np.arange(n_edges * layers, dtype=np.int64)
    return np.stack([2 * v, 2 * v + 1], axis=1)


def segment_graph_distances(
    nodes: FloatArray, edges: IntArray, limit: float
) -> tuple[IntArray, FloatArray]:
    """Segment pairs ``(P, 2)`` (``a <= b``, each segment with itself included) whose nearest end
    nodes are joined by a network path shorter than ``limit`` (mm), with that path's length.

    The same graph distance as :func:`rotomorph.contact.exclusion.graph_neighbour_pairs`
    (Dijkstra on the printed segment lengths), with its value kept.
    """
    edges = np.asarray(edges, dtype=np.int64)
    n = len(nodes)
    length = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
    graph = sp.csr_matrix(
        (np.r_[length, length], (np.r_[edges[:, 0], edges[:, 1]], np.r_[edges[:, 1], edges[:, 0]])),
        shape=(n, n),
    )
    src_l, dst_l, dist_l = [], [], []
    for start in range(0, n, _CHUNK):
        src = np.arange(start, min(start + _CHUNK, n))
        dist = dijkstra(graph, directed=False, indices=src, limit=limit)
        r, c = np.nonzero(dist < limit)
        src_l.append(src[r])
        dst_l.append(c)
        dist_l.append(dist[r, c])
    u, w, d = np.concatenate(src_l), np.concatenate(dst_l), np.concatenate(dist_l)
    # segments at each node (padded with -1)
    deg = np.bincount(edges.ravel(), minlength=n)
    inc = -np.ones((n, max(int(deg.max()), 1)), dtype=np.int64)
    fill = np.zeros(n, dtype=np.int64)
    for j, (a, b) in enumerate(edges):
        inc[a, fill[a]] = j
        fill[a] += 1
        inc[b, fill[b]] = j
        fill[b] += 1
    sa = np.repeat(inc[u], inc.shape[1], axis=1).ravel()
    sb = np.tile(inc[w], (1, inc.shape[1])).ravel()
    dd = np.repeat(d, inc.shape[1] ** 2)
    ok = (sa >= 0) & (sb >= 0)
    sa, sb, dd = sa[ok], sb[ok], dd[ok]
    lo, hi = np.minimum(sa, sb), np.maximum(sa, sb)
    key = lo * len(edges) + hi
    order = np.lexsort((dd, key))
    key, dd = key[order], dd[order]
    first = np.ones(len(key), dtype=bool)
    first[1:] = key[1:] != key[:-1]
    key, dd = key[first], dd[first]
    return np.stack([key // len(edges), key % len(edges)], axis=1), dd


def _reach(radius: FloatArray, edges_len: FloatArray, reach: float | None) -> float:
    """The single-filament reach of :func:`rotomorph.contact.exclusion.excluded_pairs`."""
    if reach is None:
        return max(0.5 * np.pi * 2.0 * float(radius.max()), float(edges_len.max()))
    return float(reach)


def stack_exclusion(
    nodes: FloatArray,
    edges: IntArray,
    directors: FloatArray,
    radius: FloatArray,
    stack: Stack,
    activation: float,
    reach: float | None = None,
) -> IntArray:
    """Sorted keys ``a * V + b`` (``a < b``, ``V = N E``) of virtual segment pairs that may not
    touch (module docstring).

    Parameters
    ----------
    nodes, edges
        The printed network (mm).
    directors
        Printed material director m1 of every segment ``(E, 3)``.
    radius
        Filament (layer) radius per segment ``(E,)`` (mm).
    stack
        The layer offsets.
    activation
        Activation distance of the barrier (mm): pairs closer than contact + activation as
        printed are fused.
    reach
        Single-filament graph reach (mm); default ``π max(r_a + r_b)/2``, at least the
        longest segment.
    """
    edges = np.asarray(edges, dtype=np.int64)
    radius = np.asarray(radius, dtype=float)
    ne = len(edges)
    o = np.abs(np.asarray(stack.offsets, dtype=float))
    n_layers = len(o)
    length = np.linalg.norm(nodes[edges[:, 1]] - nodes[edges[:, 0]], axis=1)
    base = _reach(radius, length, reach)
    pair_reach = base + 0.5 * np.pi * (o[:, None] + o[None, :])  # (N, N)
    pairs, dist = segment_graph_distances(nodes, edges, float(pair_reach.max()))
    keys = []
    big = n_layers * ne
    for k in range(n_layers):
        for m in range(n_layers):
            near = dist < pair_reach[k, m]
            e, f = pairs[near, 0], pairs[near, 1]
            a, b = k * ne + e, m * ne + f
            same = a == b
            keys.append(np.minimum(a, b)[~same] * big + np.maximum(a, b)[~same])
    # fused as printed: layer capsules closer than contact + activation
    pts = layer_points(nodes, edges, directors, stack.offsets)
    vedges = layer_edges(ne, n_layers)
    vrad = np.tile(radius, n_layers)
    vlen = np.tile(length, n_layers)
    mid = 0.5 * (pts[vedges[:, 0]] + pts[vedges[:, 1]])
    cand = (
        cKDTree(mid)
        .query_pairs(
            2.0 * float(radius.max()) + activation + float(vlen.max()), output_type="ndarray"
        )
        .reshape(-1, 2)
    )
    if len(cand):
        quads = np.ascontiguousarray(np.concatenate([vedges[cand[:, 0]], vedges[cand[:, 1]]], 1))
        d = pair_distances(np.array(pts, dtype=float), quads)
        fused = cand[d < vrad[cand[:, 0]] + vrad[cand[:, 1]] + activation]
        keys.append(pair_keys(fused, big))
    return np.unique(np.concatenate(keys)).astype(np.int64)


@dataclass(frozen=True, eq=False)
class StackOverlaps:
    """Layer pairs that interpenetrate in one configuration.

    Attributes
    ----------
    segments
        ``(P, 2)`` network segments of each pair, the lower index first.
    layers
        ``(P, 2)`` their layers (0 = bottom).
    distance
        ``(P,)`` distance between the two layer centre lines (mm).
    contact_distance
        ``(P,)`` ``r_a + r_b`` (mm): a pair interpenetrates when ``distance`` is below it.
    """

    segments: IntArray
    layers: IntArray
    distance: FloatArray
    contact_distance: FloatArray

    @property
    def count(self) -> int:
        """Number of interpenetrating layer pairs."""
        return len(self.distance)

    @property
    def deepest(self) -> float:
        """Largest penetration depth ``r_a + r_b − d`` (mm; 0 when none)."""
        return float((self.contact_distance - self.distance).max()) if self.count else 0.0

    def segment_pairs(self) -> IntArray:
        """Distinct network segment pairs ``(Q, 2)`` with at least one overlapping layer pair."""
        if not self.count:
            return np.zeros((0, 2), dtype=np.int64)
        s = np.sort(self.segments, axis=1)
        return np.unique(s, axis=0)


def stack_overlaps(
    positions: FloatArray,
    edges: IntArray,
    directors: FloatArray,
    radius: FloatArray,
    stack: Stack,
    excluded: IntArray,
    tolerance: float = 0.0,
) -> StackOverlaps:
    """Every pair of layers of two segments allowed to touch whose centre lines are closer than
    ``r_a + r_b - tolerance`` (they interpenetrate), in configuration ``positions``.

    Parameters
    ----------
    positions
        Node positions ``(n, 3)`` (mm).
    edges
        Segments ``(E, 2)``.
    directors
        Material director m1 of every segment ``(E, 3)`` in this configuration.
    radius
        Layer radius per segment ``(E,)`` (mm).
    stack
        The layer offsets.
    excluded
        Sorted virtual keys of :func:`stack_exclusion` (pairs that never touch).
    tolerance
        Depth (mm) a pressed contact may reach inside ``r_a + r_b``: the contact model's
        compliant zone (``Contact.offset``; its barrier is infinite that far inside); 0: any
        overlap counts.
    """
    edges = np.asarray(edges, dtype=np.int64)
    radius = np.asarray(radius, dtype=float)
    ne, n_layers = len(edges), stack.count
    pts = layer_points(positions, edges, directors, stack.offsets)
    vedges = layer_edges(ne, n_layers)
    vrad = np.tile(radius, n_layers)
    a, b = pts[vedges[:, 0]], pts[vedges[:, 1]]
    half = 0.5 * float(np.linalg.norm(b - a, axis=1).max())
    mid = 0.5 * (a + b)
    cand = (
        cKDTree(mid)
        .query_pairs(2.0 * float(radius.max()) + 2.0 * half, output_type="ndarray")
        .reshape(-1, 2)
    )
    empty = StackOverlaps(
        np.zeros((0, 2), dtype=np.int64), np.zeros((0, 2), dtype=np.int64), np.zeros(0), np.zeros(0)
    )
    if not len(cand):
        return empty
    cand = np.sort(cand, axis=1)
    big = ne * n_layers
    keys = cand[:, 0] * big + cand[:, 1]
    if len(excluded):  # (none excluded: every pair is tested)
        pos = np.searchsorted(excluded, keys)
        hit = (pos < len(excluded)) & (excluded[np.minimum(pos, len(excluded) - 1)] == keys)
        cand = cand[~hit]
    if not len(cand):
        return empty
    quads = np.ascontiguousarray(np.concatenate([vedges[cand[:, 0]], vedges[cand[:, 1]]], 1))
    d = pair_distances(np.ascontiguousarray(pts, dtype=float), quads)
    dmin = vrad[cand[:, 0]] + vrad[cand[:, 1]]
    bad = d < dmin - float(tolerance)
    cand = cand[bad]
    seg, lay = cand % ne, cand // ne
    swap = seg[:, 0] > seg[:, 1]  # lower segment first
    seg[swap], lay[swap] = seg[swap][:, ::-1], lay[swap][:, ::-1]
    return StackOverlaps(segments=seg, layers=lay, distance=d[bad], contact_distance=dmin[bad])
