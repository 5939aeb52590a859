"""The rigid motions along a floor: their cross products and what they span."""

from __future__ import annotations

import numpy as np

from rotomorph.solve.contact_term import _cross, tangent_rigid_modes


def test_cross_is_numpys_bit_for_bit(rng):
    for _ in range(20):
        u = rng.normal(size=3)
        for v in (rng.normal(size=3), rng.normal(size=(40, 3))):
            assert np.array_equal(_cross(u, v), np.cross(u, v))


def test_tangent_modes_slide_and_turn_a_body_on_the_floor(rng):
    nodes, twists = 7, 6
    x = rng.normal(size=(nodes, 3))
    t = rng.normal(size=(twists, 3))
    normal = np.array([0.0, 0.0, 2.0])
    pos = 4 * np.arange(nodes)
    theta = np.setdiff1d(np.arange(4 * nodes), (pos[:, None] + np.arange(3)).ravel())[:twists]
    U = tangent_rigid_modes(x, t, normal, pos, theta, 4 * nodes)
    moved = [U[k][pos[:, None] + np.arange(3)] for k in range(3)]
    # two unit translations along the floor, orthogonal
    for k in (0, 1):
        np.testing.assert_allclose(moved[k], np.tile(moved[k][0], (nodes, 1)))
        assert abs(moved[k][0] @ [0, 0, 1]) < 1e-15 and abs(np.linalg.norm(moved[k][0]) - 1) < 1e-15
    assert abs(moved[0][0] @ moved[1][0]) < 1e-15
    # the turn about the normal through the centroid, turning each frame by n . t
    r = x - x.mean(axis=0)
    np.testing.assert_allclose(moved[2], np.c_[-r[:, 1], r[:, 0], 0 * r[:, 0]], atol=1e-15)
    np.testing.assert_allclose(U[2][theta], t[:, 2])


def test_tangent_modes_are_the_vectorised_formula_bit_for_bit(rng):
    """The compiled fill writes what the NumPy expressions give (the projection of every
    Newton step on a floor depends on these rows to the last bit)."""
    nodes, twists = 30, 29
    x = rng.normal(size=(nodes, 3)) * 50.0
    t = rng.normal(size=(twists, 3))
    normal = rng.normal(size=3)
    pos = 4 * np.arange(nodes)
    theta = pos[:-1] + 3
    U = tangent_rigid_modes(x, t, normal, pos, theta, 4 * nodes)
    n = normal / np.linalg.norm(normal)
    coord = pos[:, None] + np.arange(3)
    np.testing.assert_array_equal(U[2][coord], _cross(n, x - x.mean(axis=0)))
    np.testing.assert_array_equal(U[2][theta], t @ n)
    for k in (0, 1):
        np.testing.assert_array_equal(U[k][coord], np.tile(U[k][pos[0] : pos[0] + 3], (nodes, 1)))
    assert np.count_nonzero(U[:2][:, theta]) == 0
