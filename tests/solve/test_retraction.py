"""The edge-rotation retraction: to first order the chord step (what the Newton direction and
the Armijo test assume), exact for rotations (edge lengths kept), on a single filament (tree
accumulation) and on a branched, supported network (least squares)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.solve.retraction import EdgeRotationRetraction


def _networks(rng):
    chain = np.cumsum(rng.normal(size=(8, 3)), axis=0)
    chain_edges = np.stack([np.arange(7), np.arange(1, 8)], axis=1)
    # a square with a diagonal (a cycle: not a tree) and two supported corners
    square = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float) + 0.1 * rng.normal(
        size=(4, 3)
    )
    square_edges = np.array([[0, 1], [1, 2], [2, 3], [3, 0], [0, 2]])
    return [(chain, chain_edges, []), (chain, chain_edges, [3]), (square, square_edges, [0, 1])]


@pytest.mark.parametrize("which", [0, 1, 2], ids=["free-chain", "pinned-chain", "cycle"])
def test_retraction_is_the_chord_step_to_first_order(rng, which):
    x, edges, fixed = _networks(rng)[which]
    dx = rng.normal(size=x.shape)
    dx[fixed] = 0.0
    retract = EdgeRotationRetraction(edges, len(x), np.array(fixed, dtype=np.int64))
    gaps = []
    for alpha in (1e-2, 5e-3, 2.5e-3):
        y = retract(x, dx, alpha)
        np.testing.assert_array_equal(y[fixed], x[fixed])
        gaps.append(np.abs(y - (x + alpha * dx)).max())
    # the difference from the chord is second order: it drops fourfold per halving (twofold
    # for any first-order slip, such as a wrong rotation angle or a lost axial stretch)
    np.testing.assert_allclose(gaps[0] / gaps[1], 4.0, rtol=0.05)
    np.testing.assert_allclose(gaps[1] / gaps[2], 4.0, rtol=0.05)


def test_a_rotation_step_turns_an_edge_without_stretching_it():
    """dx = w x e on the tip of one edge: the edge turns by |w| alpha exactly, length kept (a
    chord step would lengthen it by l (|w| alpha)^2 / 2)."""
    x = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    dx = np.array([[0.0, 0.0, 0.0], [0.0, 0.6, 0.0]])  # w = 0.3 about z
    retract = EdgeRotationRetraction(np.array([[0, 1]]), 2, np.array([0]))
    y = retract(x, dx, 2.0)  # a turn of 0.6 rad
    np.testing.assert_allclose(y[1], [2.0 * np.cos(0.6), 2.0 * np.sin(0.6), 0.0], atol=1e-14)
    # a pure axial step stretches it exactly like the chord
    y = retract(x, np.array([[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]]), 0.4)
    np.testing.assert_allclose(y[1], [2.2, 0.0, 0.0], atol=1e-14)


@pytest.mark.parametrize("fixed", [[], [0, 1]], ids=["free-body", "supported"])
def test_least_squares_nodes_match_the_sparse_formula_to_the_bit(rng, fixed):
    """The compiled right-hand side accumulates in SciPy's order: the nodes equal those of
    ``Bf^T (targets - Bd xd)`` solved with the same factorization, bit for bit."""
    import scipy.sparse as sp

    from rotomorph.solve.retraction import _edge_targets

    x, edges, _ = _networks(rng)[2]
    dx = rng.normal(size=x.shape)
    dx[fixed] = 0.0
    retract = EdgeRotationRetraction(edges, len(x), np.array(fixed, dtype=np.int64))
    alpha = 0.3
    y = retract(x, dx, alpha)
    n, e = len(x), len(edges)
    B = sp.csr_matrix(
        (np.r_[-np.ones(e), np.ones(e)], (np.r_[np.arange(e), np.arange(e)], edges.T.ravel())),
        shape=(e, n),
    )
    fix, free = retract.fixed, retract.free
    target = np.empty((e, 3))
    _edge_targets(x, dx, alpha, np.ascontiguousarray(edges, dtype=np.int64), target)
    xd = x[fix] + (alpha * dx[fix] if not fixed else 0.0)
    rhs = B[:, free].tocsc().T.tocsr() @ (target - B[:, fix].tocsc() @ xd)
    expected = np.empty_like(x)
    expected[fix] = xd
    expected[free] = retract._lu.solve(np.ascontiguousarray(rhs))
    np.testing.assert_array_equal(y, expected)


def test_split_and_join_of_a_step_are_the_layout_indexing(rng):
    """The compiled gather/scatter of :meth:`RodObjective.retract` against NumPy indexing:
    interleaved positions and twist angles, some DOFs fixed."""
    from rotomorph.solve.retraction import join_step, split_step

    nodes = 6
    pos = 4 * np.arange(nodes)
    theta = pos[:-1] + 3
    count = 4 * nodes - 1
    free = np.setdiff1d(np.arange(count), [0, 1, 2, 7])
    u_base = rng.normal(size=count)
    q, d = rng.normal(size=len(free)), rng.normal(size=len(free))
    index = (pos[:, None] + np.arange(3)).ravel()
    u, du = np.empty(count), np.empty(count)
    x, dx = np.empty((nodes, 3)), np.empty((nodes, 3))
    split_step(u_base, free, q, d, pos, u, du, x, dx)
    u_ref = u_base.copy()
    u_ref[free] = q
    du_ref = np.zeros(count)
    du_ref[free] = d
    np.testing.assert_array_equal(u, u_ref)
    np.testing.assert_array_equal(du, du_ref)
    np.testing.assert_array_equal(x, u_ref[index].reshape(-1, 3))
    np.testing.assert_array_equal(dx, du_ref[index].reshape(-1, 3))
    moved = rng.normal(size=(nodes, 3))
    out = np.empty(len(free))
    join_step(u, du, 0.7, moved, pos, theta, free, out)
    u_ref[index] = moved.ravel()
    u_ref[theta] += 0.7 * du_ref[theta]
    np.testing.assert_array_equal(out, u_ref[free])
