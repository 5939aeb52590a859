"""Quasi-static toppling of a rigid point set onto a plane (lattice.resting)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.resting import resting_rotation

UP = np.array([0.0, 0.0, 1.0])


def _rotation(axis: np.ndarray, angle: float) -> np.ndarray:
    k = axis / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def _rest(points: np.ndarray, weights: np.ndarray) -> np.ndarray:
    R, t = resting_rotation(points, weights, UP)
    assert np.allclose(R @ R.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)
    return points @ R.T + t


def _support_contains_centre(x: np.ndarray, w: np.ndarray, tol: float = 1e-7) -> bool:
    """Whether the vertical through the centre of mass meets the support polygon (area > 0)."""
    from scipy.spatial import ConvexHull

    low = x[x[:, 2] - x[:, 2].min() <= tol][:, :2]
    c = (w @ x / w.sum())[:2]
    hull = ConvexHull(low)
    # inside when every facet's signed distance (normal . p + offset) is <= 0
    return bool(np.all(hull.equations[:, :2] @ c + hull.equations[:, 2] <= tol))


def test_a_tilted_box_topples_onto_a_face_with_its_centre_over_it() -> None:
    box = np.array([[x, y, z] for x in (0, 4) for y in (0, 2) for z in (0, 1)], dtype=float)
    w = np.ones(8)
    rng = np.random.default_rng(3)
    for _ in range(8):
        P = box @ _rotation(rng.normal(size=3), rng.uniform(0.1, np.pi)).T
        P[:, 2] -= P[:, 2].min()
        X = _rest(P, w)
        # a rigid motion, lowest point kept on the plane, four corners down, centre over them
        d0 = np.linalg.norm(P[:, None] - P[None], axis=2)
        assert np.allclose(np.linalg.norm(X[:, None] - X[None], axis=2), d0, atol=1e-9)
        assert X[:, 2].min() == pytest.approx(0.0, abs=1e-9)
        assert np.sum(X[:, 2] < 1e-7) == 4
        assert _support_contains_centre(X, w)
        # each turn lowers the centre of mass
        assert (X[:, 2].mean()) <= P[:, 2].mean() + 1e-12


def test_a_body_resting_on_a_face_does_not_move() -> None:
    g = np.linspace(0.0, 10.0, 6)
    plate = np.array([[x, y, 0.0] for x in g for y in g])
    plate = np.vstack([plate, [[5.0, 5.0, 2.0]]])  # a knob on top
    R, t = resting_rotation(plate, np.ones(len(plate)), UP)
    assert np.allclose(R, np.eye(3)) and np.allclose(t, 0.0)


def test_a_saddle_balanced_on_its_low_corners_rocks_over() -> None:
    # z = (x^2 - y^2)/8 on a grid, turned so its two low corners (y = +-4) touch the plane:
    # balanced on a segment (an unstable rigid equilibrium), it must tip onto a face
    g = np.linspace(-4.0, 4.0, 9)
    S = np.array([[x, y, (x * x - y * y) / 8.0] for x in g for y in g])
    S[:, 2] -= S[:, 2].min()
    w = np.ones(len(S))
    assert np.sum(S[:, 2] < 1e-9) == 2
    X = _rest(S, w)
    assert np.sum(X[:, 2] - X[:, 2].min() < 1e-7) >= 3
    assert _support_contains_centre(X, w)
    assert X[:, 2].mean() < S[:, 2].mean() - 1e-3


def test_weights_move_the_resting_face() -> None:
    # a triangular prism, heavy at one end: it must rest with the heavy end low
    box = np.array([[x, y, z] for x in (0, 6) for y in (0, 1) for z in (0, 1)], dtype=float)
    w = np.where(box[:, 0] > 3, 10.0, 1.0)
    P = box @ _rotation(np.array([0.0, 1.0, 0.0]), 0.5).T  # on an edge, tilted
    P[:, 2] -= P[:, 2].min()
    X = _rest(P, w)
    assert _support_contains_centre(X, w)


def test_bad_input_names_the_field() -> None:
    with pytest.raises(InvalidParameterError, match="points"):
        resting_rotation(np.zeros((4, 2)), np.ones(4), UP)
    with pytest.raises(InvalidParameterError, match="points"):
        resting_rotation(np.zeros((4, 3)), np.zeros(4), UP)
