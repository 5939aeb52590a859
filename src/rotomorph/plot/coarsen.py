"""Coarser segments for drawing tubes: runs of short segments merged into longer ones.

A simulated filament often has segments much shorter than its radius (30 mm of filament in
600 segments of 0.05 mm at a radius of 0.3 mm). Drawn as tubes, such segments cost memory,
drawing time and file size but add nothing visible. :func:`coarsen_network` merges
consecutive segments along the unbranched runs of a network (between nodes whose degree is
not 2) into segments of at most ``length`` millimetres that turn by at most ``max_turn``
radians, in every given state, so that one coarse topology serves a whole heating ramp. Ends
and branch nodes are always kept. A coarse segment's chord leaves the fine centre line by at
most about ``length · max_turn / 4``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.errors import InvalidParameterError

__all__ = ["CoarseNetwork", "coarsen_network"]


@dataclass(frozen=True, eq=False)
class CoarseNetwork:
    """A network's segments merged into coarser ones (node indices of the fine network).

    Attributes
    ----------
    edges
        ``(C, 2)`` end nodes of the coarse segments (indices into the fine nodes).
    groups
        For each coarse segment, the fine segment indices it replaces, in order along it.
    """

    edges: IntArray
    groups: tuple[IntArray, ...]

    @property
    def middle(self) -> IntArray:
        """``(C,)`` the middle fine segment of each coarse one (for per-segment directions,
        which must not be averaged across a flip of the active side)."""
        return np.array([g[len(g) // 2] for g in self.groups], dtype=np.int64)

    def mean(self, values: FloatArray) -> FloatArray:
        """Mean over each group of per-fine-segment ``values`` ``(..., E)`` → ``(..., C)``,
        ignoring NaN (NaN where a group has no finite value)."""
        v = np.asarray(values, dtype=float)
        order = np.concatenate(self.groups)
        starts = np.cumsum([0] + [len(g) for g in self.groups[:-1]])
        part = v[..., order]
        finite = np.isfinite(part)
        count = np.add.reduceat(finite.astype(float), starts, axis=-1)
        total = np.add.reduceat(np.where(finite, part, 0.0), starts, axis=-1)
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(count > 0, total / count, np.nan)


def _runs(edges: IntArray, n: int) -> list[tuple[list[int], list[int]]]:
    """Unbranched runs ``(nodes, segments)``: walks between nodes of degree ≠ 2, then the
    closed loops that have none."""
    incident: list[list[int]] = [[] for _ in range(n)]
    for j, (a, b) in enumerate(edges):
        incident[a].append(j)
        incident[b].append(j)
    degree = [len(i) for i in incident]
    seen = np.zeros(len(edges), dtype=bool)

    def walk(start: int, first: int) -> tuple[list[int], list[int]]:
        nodes, segs = [start], []
        node, seg = start, first
        while True:
            seen[seg] = True
            segs.append(seg)
            a, b = edges[seg]
            node = int(b) if a == node else int(a)
            nodes.append(node)
            if degree[node] != 2 or node == start:
                return nodes, segs
            nxt = [j for j in incident[node] if not seen[j]]
            if not nxt:
                return nodes, segs
            seg = nxt[0]

    runs = []
    for start in range(n):
        if degree[start] != 2:
            for j in incident[start]:
                if not seen[j]:
                    runs.append(walk(start, j))
    for j in range(len(edges)):  # closed loops of degree-2 nodes only
        if not seen[j]:
            runs.append(walk(int(edges[j, 0]), j))
    return runs


def coarsen_network(
    positions: FloatArray,
    edges: IntArray,
    length: float,
    *,
    max_turn: float = 0.2,
) -> CoarseNetwork:
    """Merge consecutive segments of unbranched runs into segments for drawing.

    Parameters
    ----------
    positions
        Node positions ``(N, 3)`` or ``(S, N, 3)`` for S states (mm); the limits hold in
        every state.
    edges
        Segments ``(E, 2)``.
    length
        Longest coarse segment (mm), summed over its fine segments; a fine segment longer
        than this stays as it is.
    max_turn
        Largest total turning angle inside a coarse segment (rad).

    Returns
    -------
    CoarseNetwork
    """
    pos = np.asarray(positions, dtype=float)
    pos = pos[None] if pos.ndim == 2 else pos
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if pos.ndim != 3 or pos.shape[2] != 3:
        raise InvalidParameterError("positions", f"must be (N, 3) or (S, N, 3); got {pos.shape}")
    if not (np.isfinite(length) and length > 0):
        raise InvalidParameterError("length", f"must be finite and > 0 mm; got {length}")
    if not (np.isfinite(max_turn) and max_turn >= 0):
        raise InvalidParameterError("max_turn", f"must be finite and >= 0 rad; got {max_turn}")
    vec = pos[:, e[:, 1]] - pos[:, e[:, 0]]  # (S, E, 3)
    seg_len = np.linalg.norm(vec, axis=2).max(axis=0)  # longest over the states
    unit = vec / np.maximum(np.linalg.norm(vec, axis=2, keepdims=True), 1e-300)
    coarse_edges: list[tuple[int, int]] = []
    groups: list[IntArray] = []
    for nodes, segs in _runs(e, pos.shape[1]):
        # direction of each segment along the walk, and the turn at each interior node
        sign = np.array([1.0 if e[s, 0] == nodes[i] else -1.0 for i, s in enumerate(segs)])
        t = unit[:, segs] * sign[None, :, None]
        cos = np.clip(np.einsum("sij,sij->si", t[:, :-1], t[:, 1:]), -1.0, 1.0)
        turn = np.arccos(cos).max(axis=0) if len(segs) > 1 else np.zeros(0)
        first, acc_len, acc_turn = 0, float(seg_len[segs[0]]), 0.0
        for i in range(1, len(segs) + 1):
            if i < len(segs):
                step_len, step_turn = float(seg_len[segs[i]]), float(turn[i - 1])
                if acc_len + step_len <= length and acc_turn + step_turn <= max_turn:
                    acc_len += step_len
                    acc_turn += step_turn
                    continue
            coarse_edges.append((nodes[first], nodes[i]))
            groups.append(np.asarray(segs[first:i], dtype=np.int64))
            if i < len(segs):
                first, acc_len, acc_turn = i, float(seg_len[segs[i]]), 0.0
    return CoarseNetwork(np.array(coarse_edges, dtype=np.int64).reshape(-1, 2), tuple(groups))
