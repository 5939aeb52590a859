"""Broad phase against brute force: no allowed segment pair within contact + activation
distance is ever left out, at a configuration and along a straight step (every contact force,
every step bound and every path check rests on that)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact import Contact, ContactPotential
from rotomorph.contact.distance import pair_distances
from rotomorph.design.network import Network


def _tangle(rng: np.random.Generator) -> tuple[Network, np.ndarray]:
    """Six random-walk filaments of 12 nodes, printed 120 mm apart in z (no pair between them
    fused) and returned crowded into a small box (many near pairs): (network, positions)."""
    walks, edges = [], []
    for c in range(6):
        steps = rng.normal(size=(12, 3))
        steps *= 0.7 / np.linalg.norm(steps, axis=1, keepdims=True)
        walks.append(rng.uniform(-1.5, 1.5, 3) + np.cumsum(steps, axis=0))
        edges.append(12 * c + np.stack([np.arange(11), np.arange(1, 12)], axis=1))
    lift = np.repeat(120.0 * np.arange(6), 12)[:, None] * [0.0, 0.0, 1.0]
    crowded = np.vstack(walks)
    return Network(crowded + lift, np.vstack(edges)), np.ascontiguousarray(crowded)


def _found(cand, pot) -> set[tuple[int, int]]:
    """Segment pairs (i < j) among the candidates' segment-segment quadruples."""
    index = {tuple(e): k for k, e in enumerate(pot.edges.tolist())}
    out = set()
    for q in cand.quads.tolist():
        a, b = index.get((q[0], q[1])), index.get((q[2], q[3]))
        if a is not None and b is not None and q[0] != q[1]:
            out.add((min(a, b), max(a, b)))
    return out


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_no_near_pair_is_left_out(seed):
    rng = np.random.default_rng(seed)
    net, x = _tangle(rng)
    pot = ContactPotential(Contact(radius=0.2, activation_distance=0.05), net)
    ne = net.n_edges
    i, j = np.triu_indices(ne, 1)
    allowed = ~np.isin(i * ne + j, pot.excluded)
    i, j = i[allowed], j[allowed]
    quads = np.ascontiguousarray(np.hstack([net.edges[i], net.edges[j]]))
    reach = 2 * 0.2 + pot.dhat
    # at the configuration (margin 0: the tightest the broad phase is ever asked for)
    near = {(a, b) for a, b, d in zip(i, j, pair_distances(x, quads), strict=True) if d < reach}
    assert len(near) > 20  # the tangle has plenty
    assert near <= _found(pot._build_candidates(x, 0.0), pot)
    # along a straight step: any pair within reach at some point of the path
    dx = rng.normal(scale=0.4, size=x.shape)
    ts = np.linspace(0.0, 1.0, 41)
    swept = np.min([pair_distances(np.ascontiguousarray(x + t * dx), quads) for t in ts], axis=0)
    path_near = {(a, b) for a, b, d in zip(i, j, swept, strict=True) if d < reach}
    assert len(path_near) > len(near)
    assert path_near <= _found(pot._build_candidates(x, 0.0, step=dx), pot)
