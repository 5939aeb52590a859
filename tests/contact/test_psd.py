"""The compiled positive-semidefinite projection against LAPACK's eigen-decomposition."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact.psd import psd_project


def _lapack_projection(h: np.ndarray) -> np.ndarray:
    vals, vecs = np.linalg.eigh(h)
    return (vecs * np.maximum(vals, 0.0)) @ vecs.T


def _project(h: np.ndarray) -> np.ndarray:
    n = len(h)
    out = np.empty((n, n))
    psd_project(h, out, np.empty((n, n)), np.empty(n), np.empty(n))
    return out


@pytest.mark.parametrize("n", [1, 2, 3, 12])
@pytest.mark.parametrize("kind", ["full", "low-rank", "scaled", "diagonal"])
def test_projection_matches_lapack(n, kind, rng):
    for _ in range(20):
        a = rng.standard_normal((n, n))
        h = a + a.T
        if kind == "low-rank":  # the barrier blocks: rank <= 5, one eigenvalue of each sign here
            u = rng.standard_normal((n, 2))
            h = u @ np.diag([3.0, -2.0]) @ u.T
        elif kind == "scaled":
            h *= 10.0 ** rng.uniform(-12, 12)
        elif kind == "diagonal":
            h = np.diag(rng.standard_normal(n))
        out = _project(h)
        assert np.array_equal(out, out.T)
        assert np.abs(out - _lapack_projection(h)).max() <= 1e-13 * np.abs(h).max()


def test_projection_in_place_and_of_a_semidefinite_matrix(rng):
    a = rng.standard_normal((12, 5))
    h = a @ a.T  # already positive semidefinite: kept
    work = h.copy()
    psd_project(work, work, np.empty((12, 12)), np.empty(12), np.empty(12))
    assert np.abs(work - h).max() <= 1e-13 * np.abs(h).max()
    assert np.abs(_project(-h)).max() <= 1e-13 * np.abs(h).max()  # negative semidefinite: 0
