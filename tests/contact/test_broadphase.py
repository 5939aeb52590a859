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


def _grid(rng: np.random.Generator) -> tuple[Network, np.ndarray]:
    """Two crossing layers of four wavy filaments (12 nodes each, 0.8 mm apart, layers 0.5 mm
    apart), printed 120 mm apart in z (no pair fused): (network, positions)."""
    s = np.linspace(0.0, 5.0, 12)
    lines, edges = [], []
    for c in range(8):
        off = 0.8 * (c % 4)
        wave = 0.1 * np.sin(2.0 * s + rng.uniform(0.0, 2.0 * np.pi))
        if c < 4:
            pts = np.stack([s, off + wave, np.zeros(12)], axis=1)
        else:
            pts = np.stack([off + 0.4 + wave, s, np.full(12, 0.5)], axis=1)
        lines.append(pts + rng.normal(scale=0.01, size=pts.shape))
        edges.append(12 * c + np.stack([np.arange(11), np.arange(1, 12)], axis=1))
    x = np.vstack(lines)
    lift = np.repeat(120.0 * np.arange(8), 12)[:, None] * [0.0, 0.0, 1.0]
    return Network(x + lift, np.vstack(edges)), np.ascontiguousarray(x)


def _shift(rng: np.random.Generator, shape: tuple[int, ...], scale: float) -> np.ndarray:
    """Each filament translated by its own random vector of length up to ``scale`` (pairs of
    filaments close at up to twice that), plus a small jitter per node."""
    shift = rng.normal(size=(8, 3))
    shift *= rng.uniform(0.0, scale, (8, 1)) / np.linalg.norm(shift, axis=1, keepdims=True)
    return np.repeat(shift, 12, axis=0) + rng.normal(scale=0.05 * scale, size=shape)


def _wall_clearance(pot: ContactPotential, x: np.ndarray) -> float:
    """Smallest distance over where the barrier is infinite (``r_a + r_b - offset``)."""
    d, wall = pot._distances(x)
    return float((d / wall).min()) if len(d) else 2.0


def _sets(pairs: np.ndarray) -> set[tuple[int, ...]]:
    return {tuple(p) for p in pairs.tolist()}


@pytest.mark.parametrize("seed", [0, 1])
def test_reused_candidates_give_the_pairs_of_a_fresh_broad_phase(seed):
    """A random walk of two crossing layers of filaments, kept where the barrier is finite and
    pressing into contact at times, with the padded candidate set reused many times (a Verlet
    list): every pair within reach is evaluated (the same active pairs and energy as a fresh
    broad phase at each configuration),
    the step bound's pairs picked out of the reused set equal a fresh swept broad phase's for
    steps inside and beyond what the set covers, and the step bounds are identical."""
    rng = np.random.default_rng(seed)
    net, base = _grid(rng)
    contact = Contact(radius=0.2)
    pot = ContactPotential(contact, net)
    judge = ContactPotential(contact, net)  # admissibility checks, apart from pot's reuse
    pad = pot._pad
    x = base
    reuses = active = steps_reused = swept = 0
    for _ in range(150):
        step = 0.1 * (base - x) + _shift(rng, x.shape, 0.5 * pad)
        while _wall_clearance(judge, x + step) <= 1.0:  # back off until the barrier is finite
            step *= 0.5
        x = np.ascontiguousarray(x + step)
        before = pot._cache
        e, g, h = pot.evaluate_blocks(x, True, 1)
        reuses += before is not None and pot._cache is before
        fresh = ContactPotential(contact, net)
        fresh._pad = 0.0  # a broad phase at x itself
        e0, g0, h0 = fresh.evaluate_blocks(x, True, 1)
        assert np.isfinite(e0) and e == pytest.approx(e0, rel=1e-12, abs=1e-300)
        np.testing.assert_allclose(g, g0, rtol=1e-12, atol=1e-12 * np.abs(g0).max())
        assert _sets(h.quads) == _sets(h0.quads)
        active += len(h.quads)
        for scale in (0.05, 0.2, 0.5, 0.7, 1.0, 3.0):  # steps from x, some beyond the reused sets
            dx = _shift(rng, x.shape, scale * pad)
            steps_reused += pot._cache.near.covers(x, x + dx)
            seg, node = pot._swept_pairs(x, dx)
            seg0, node0 = pot._self_pairs(x, x + dx, 0.0)
            assert _sets(seg) == _sets(seg0) and len(seg) == len(seg0)
            assert _sets(node) == _sets(node0) and len(node) == len(node0)
            swept += len(seg0) + len(node0)
            assert pot.step_bound(x, dx) == ContactPotential(contact, net).step_bound(x, dx)
    assert 50 < reuses < 140  # both reuse and fresh broad phases, many times
    assert active > 100 and steps_reused > 150 and swept > 5000  # of 900 steps: both kinds


def test_step_bounds_from_one_start_share_its_distances(rng):
    """The conservative advancement of several steps from one start over the same pairs
    reuses the distances at the start (filled in as first needed, exactly the pairs'
    distances there): every bound equals one computed from scratch."""
    from rotomorph.contact.ccd import pair_step_bound

    net, base = _grid(rng)
    pot = ContactPotential(Contact(radius=0.2), net)
    x = np.ascontiguousarray(base)
    cand = pot._build_candidates(x, 0.0, step=_shift(rng, x.shape, 2.0))
    quads, dmin = cand.quads, cand.dmin
    shared = np.full(len(quads), np.nan)
    bounds = []
    for scale in (0.02, 0.1, 0.3, 0.6) * 3:
        dx = np.ascontiguousarray(_shift(rng, x.shape, scale))
        for close in (0.9, 1.0):
            t = pair_step_bound(x, dx, quads, dmin, close, 100_000, shared)
            fresh = pair_step_bound(x, dx, quads, dmin, close, 100_000, np.full(len(quads), np.nan))
            assert t == fresh
            bounds.append(t)
    known = ~np.isnan(shared)
    assert known.sum() > 20 and len(set(bounds)) > 4 and min(bounds) < 1.0
    assert np.array_equal(shared[known], pair_distances(x, quads)[known])


def _all_pairs(x0, x1, edges, incident, seg_share, node_share, excluded):
    """Every segment pair and node–segment pair whose boxes over ``x0 -> x1`` come closer than
    the sum of their shares and that may touch, by brute force over all pairs (sets)."""
    ne = len(edges)
    seg_pts = np.concatenate([x0[edges], x1[edges]], axis=1)  # (E, 4, 3)
    lo = np.concatenate([seg_pts.min(axis=1), np.minimum(x0, x1)])
    hi = np.concatenate([seg_pts.max(axis=1), np.maximum(x0, x1)])
    share = np.concatenate([seg_share, node_share])
    gap = np.maximum(np.maximum(lo[None] - hi[:, None], lo[:, None] - hi[None]), 0.0)
    reach = share[:, None] + share[None]
    near = ((gap**2).sum(axis=2) < reach**2) & (gap < reach[..., None]).all(axis=2)
    blocked = set(excluded.tolist())

    def touch(a: int, b: int) -> bool:
        return a != b and min(a, b) * ne + max(a, b) not in blocked

    seg = {(a, b) for a in range(ne) for b in range(a + 1, ne) if near[a, b] and touch(a, b)}
    node = {
        (n, e)
        for n in range(len(x0))
        for e in range(ne)
        if near[ne + n, e] and all(touch(f, e) for f in incident[n] if f >= 0)
    }
    return seg, node


@pytest.mark.parametrize("seed", range(4))
def test_near_pairs_equal_brute_force(seed):
    """The compiled broad phase proposes exactly the pairs of an all-pairs test (each pair
    once), at a configuration and along a step, on a crumpled lattice-like sheet of filaments
    lifted out of its plane (many boxes in one sweep window, many exclusions)."""
    from rotomorph.contact.broadphase import near_pairs
    from rotomorph.contact.exclusion import excluded_pairs

    rng = np.random.default_rng(seed)
    rows, cols = 6, 9
    u, v = np.meshgrid(np.linspace(0.0, 8.0, cols), np.linspace(0.0, 5.0, rows))
    idx = np.arange(rows * cols).reshape(rows, cols)
    edges = np.vstack(
        [
            np.stack([idx[:, :-1].ravel(), idx[:, 1:].ravel()], axis=1),
            np.stack([idx[:-1].ravel(), idx[1:].ravel()], axis=1),
        ]
    )
    flat = np.stack([u.ravel(), v.ravel(), np.zeros(u.size)], axis=1)
    lift = rng.uniform(1.0, 4.0) * np.sin(u / rng.uniform(1.5, 3.0)) * np.cos(v / 2.0)
    x0 = flat + np.stack([0 * u, 0 * u, lift], axis=-1).reshape(-1, 3)
    x0 = x0 + rng.normal(scale=0.15, size=x0.shape)
    radius = np.full(len(edges), 0.2)
    excluded = excluded_pairs(flat, edges, radius, 0.02, None)
    deg = np.bincount(edges.ravel(), minlength=len(x0))
    incident = -np.ones((len(x0), deg.max()), dtype=np.int64)
    fill = np.zeros(len(x0), dtype=np.int64)
    for k, (a, b) in enumerate(edges):
        incident[a, fill[a]], incident[b, fill[b]] = k, k
        fill[a] += 1
        fill[b] += 1
    share = rng.uniform(0.3, 0.9, len(edges))
    node_share = rng.uniform(0.3, 0.9, len(x0))
    for x1 in (x0, x0 + rng.normal(scale=0.5, size=x0.shape)):
        seg, node = near_pairs(x0, x1, edges, incident, share, node_share, excluded)
        want_seg, want_node = _all_pairs(x0, x1, edges, incident, share, node_share, excluded)
        assert len(want_seg) > 30 and len(want_node) > 30
        assert _sets(seg) == want_seg and len(seg) == len(want_seg)
        assert _sets(node) == want_node and len(node) == len(want_node)
