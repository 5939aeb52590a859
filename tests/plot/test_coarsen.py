"""Coarser drawing segments: every fine segment in one group, ends and branches kept, the
coarse chords close to the fine centre line in every state."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.plot.coarsen import coarsen_network


def helix(n=601, length=30.0, radius=1.5, pitch=2.4):
    """(N, 3) nodes of a helix of arc length ``length`` and its chain edges."""
    turns = length / np.hypot(2 * np.pi * radius, pitch)
    t = np.linspace(0.0, 2 * np.pi * turns, n)
    pts = np.c_[radius * np.cos(t), radius * np.sin(t), pitch * t / (2 * np.pi)]
    return pts, np.c_[np.arange(n - 1), np.arange(1, n)]


def _check_cover(coarse, edges):
    order = np.concatenate(coarse.groups)
    assert sorted(order.tolist()) == list(range(len(edges)))  # each fine segment once
    for (a, b), g in zip(coarse.edges, coarse.groups, strict=True):
        # a group is a connected run from a to b
        nodes = {a}
        for s in g:
            u, v = edges[s]
            assert u in nodes or v in nodes
            nodes |= {u, v}
        assert b in nodes


def _chord_error(pos, coarse, edges):
    worst = 0.0
    for (a, b), g in zip(coarse.edges, coarse.groups, strict=True):
        pa, pb = pos[a], pos[b]
        d = pb - pa
        inner = np.unique(edges[g])
        q = pos[inner] - pa
        s = np.clip(q @ d / max(d @ d, 1e-300), 0, 1)
        worst = max(worst, float(np.linalg.norm(q - s[:, None] * d, axis=1).max()))
    return worst


def test_a_fine_helix_is_merged_within_the_limits_in_every_state():
    straight = np.c_[np.linspace(0, 30, 601), np.zeros(601), np.zeros(601)]
    coil, edges = helix()
    states = np.stack([straight, 0.5 * (straight + coil), coil])
    length, turn = 0.3, 0.2
    coarse = coarsen_network(states, edges, length, max_turn=turn)
    assert 100 < len(coarse.edges) < 600 / 2  # far fewer, but not one per turn
    _check_cover(coarse, edges)
    assert coarse.edges[0, 0] == 0 and coarse.edges[-1, 1] == 600  # the ends are kept
    for pos in states:
        seg = np.linalg.norm(pos[coarse.edges[:, 1]] - pos[coarse.edges[:, 0]], axis=1)
        assert seg.max() <= length + 1e-12
        assert _chord_error(pos, coarse, edges) <= length * turn / 4
    # a tighter turn limit gives more segments; segments longer than the limit stay
    assert len(coarsen_network(states, edges, length, max_turn=0.05).edges) > len(coarse.edges)
    assert len(coarsen_network(states, edges, 0.01).edges) == len(edges)


def test_branch_nodes_and_loops_are_kept():
    # a plus sign: four arms of 10 fine segments from a centre node 0, and a separate ring
    edges, nodes = [], [np.zeros(3)]
    directions = np.array([[1.0, 0, 0], [0, 1.0, 0], [-1.0, 0, 0], [0, -1.0, 0]])
    for d in directions:
        prev = 0
        for i in range(1, 11):
            nodes.append(d * 0.1 * i)
            edges.append((prev, len(nodes) - 1))
            prev = len(nodes) - 1
    ring0 = len(nodes)
    phi = np.linspace(0, 2 * np.pi, 40, endpoint=False)
    nodes += list(np.c_[5 + np.cos(phi), np.sin(phi), np.zeros(40)])
    edges += [(ring0 + i, ring0 + (i + 1) % 40) for i in range(40)]
    pos, edges = np.array(nodes), np.array(edges)
    coarse = coarsen_network(pos, edges, 0.45, max_turn=0.5)
    _check_cover(coarse, edges)
    at_centre = [g for (a, b), g in zip(coarse.edges, coarse.groups, strict=True) if 0 in (a, b)]
    assert len(at_centre) == 4  # the branch node ends four coarse segments
    ring = [g for g in coarse.groups if g[0] >= 40]
    assert 8 <= len(ring) < 40  # the loop is merged (turn 0.16 rad per fine segment)
    assert _chord_error(pos, coarse, edges) <= 0.45 * 0.5 / 4


def test_group_means_and_middles():
    pos, edges = helix(n=21)
    coarse = coarsen_network(pos, edges, 100.0, max_turn=100.0)
    assert len(coarse.edges) == 1 and coarse.middle.tolist() == [10]
    v = np.arange(20.0)
    v[3] = np.nan
    assert coarse.mean(v)[0] == pytest.approx(np.nanmean(v))
    two = np.stack([v, np.full(20, np.nan)])
    out = coarse.mean(two)
    assert out.shape == (2, 1) and np.isnan(out[1, 0])


def test_bad_input_is_refused():
    pos, edges = helix(n=5)
    with pytest.raises(InvalidParameterError, match="length"):
        coarsen_network(pos, edges, 0.0)
    with pytest.raises(InvalidParameterError, match="max_turn"):
        coarsen_network(pos, edges, 1.0, max_turn=-1.0)
    with pytest.raises(InvalidParameterError, match="positions"):
        coarsen_network(pos[:, :2], edges, 1.0)
