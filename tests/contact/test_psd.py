"""The compiled positive-semidefinite projections against LAPACK's eigen-decomposition."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact.barrier import pair_barrier
from rotomorph.contact.distance import pair_distances
from rotomorph.contact.psd import psd_project, psd_project_in


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


@pytest.mark.parametrize("k", [1, 4, 5, 9])
def test_projection_on_a_known_range_matches_lapack(k, rng):
    """``psd_project_in``: the eigen-decomposition done on the k-dimensional range only."""
    for _ in range(20):
        q = np.linalg.qr(rng.standard_normal((12, k)))[0]
        s = rng.standard_normal((k, k))
        h = q @ (s + s.T) @ q.T
        h = 0.5 * (h + h.T)
        out = np.empty((12, 12))
        ok = psd_project_in(h, out, np.ascontiguousarray(q), np.empty((k, 12)), np.empty((k, k)),
                            np.empty(k), np.empty(k))  # fmt: skip
        assert ok and np.array_equal(out, out.T)
        assert np.abs(out - _lapack_projection(h)).max() <= 1e-13 * np.abs(h).max()
    bad = np.full((12, 12), np.nan)
    assert not psd_project_in(bad, out, q, np.empty((k, 12)), np.empty((k, k)), np.empty(k),
                              np.empty(k))  # fmt: skip


def _pair(kind: str, rng: np.random.Generator) -> np.ndarray:
    """Four points p0 p1 q0 q1 whose closest points are of the given kind."""
    p0, p1 = rng.standard_normal(3), rng.standard_normal(3)
    if kind == "crossing":  # both closest points inside the segments
        m, n = 0.5 * (p0 + p1), np.cross(p1 - p0, rng.standard_normal(3))
        d = np.cross(p1 - p0, n)
        q0 = m + 0.3 * n / np.linalg.norm(n) - d * rng.uniform(0.2, 0.6)
        q1 = q0 + d * rng.uniform(0.9, 1.5)
    elif kind == "end-edge":  # an end of one against the inside of the other
        n = np.cross(p1 - p0, rng.standard_normal(3))
        q0 = p0 + rng.uniform(0.2, 0.8) * (p1 - p0) + 0.4 * n / np.linalg.norm(n)
        q1 = q0 + n / np.linalg.norm(n) + 0.1 * rng.standard_normal(3)
    elif kind == "ends":  # two ends closest
        q0 = p1 + 0.3 * (p1 - p0) / np.linalg.norm(p1 - p0) + 0.05 * rng.standard_normal(3)
        q1 = q0 + (p1 - p0) + 0.2 * rng.standard_normal(3)
    elif kind == "node":  # a node against a segment (its first point repeated)
        p1 = p0
        q0 = p0 + rng.standard_normal(3)
        q1 = q0 + rng.standard_normal(3)
    elif kind == "sphere":  # a segment against a point
        q0 = rng.standard_normal(3) + 2.0
        q1 = q0
    else:  # "parallel": side by side, nearly parallel, overlapping (mollified)
        q0 = p0 + 0.5 * (p1 - p0) + 0.4 * np.cross(p1 - p0, [0.0, 0.0, 1.0])
        q1 = q0 + (p1 - p0) * 1.1 + 1e-3 * rng.standard_normal(3)
    return np.ascontiguousarray([p0, p1, q0, q1])


@pytest.mark.parametrize("kind", ["crossing", "end-edge", "ends", "node", "sphere", "parallel"])
def test_projected_barrier_hessian_equals_the_projection_of_the_exact_one(kind, rng):
    """The barrier's projected pair Hessian (taken from the Hessian's structure: closed form
    where two points are closest, a 4- or 5-dimensional range otherwise; all 12 dimensions
    with a mollifier term) equals the 12 x 12 eigen-decomposition of its exact Hessian to
    round-off, at gaps across the activation distance."""
    pairs = np.array([[0, 1, 2, 3]])
    indefinite = 0
    for _ in range(30):
        x = _pair(kind, rng)
        d = pair_distances(x, pairs)[0]
        dhat = 0.05 * d
        dmin = np.array([d - dhat * rng.uniform(0.01, 0.99)])
        a, b = x[1] - x[0], x[3] - x[2]
        moll = np.array([1e-3 * (a @ a) * (b @ b) if kind == "parallel" else 0.0])
        hs = []
        for need in (1, 2):
            h = np.zeros((1, 12, 12))
            e = pair_barrier(x, pairs, dmin, np.ones(1), moll, dhat, 1.0, False, need,
                             np.zeros((4, 3)), h, np.empty(1))  # fmt: skip
            assert np.isfinite(e) and e > 0
            hs.append(h[0])
        exact, projected = hs
        assert np.abs(projected - _lapack_projection(exact)).max() <= 1e-12 * np.abs(exact).max()
        indefinite += np.linalg.eigvalsh(exact).min() < -1e-8 * np.abs(exact).max()
    assert indefinite > 20  # the projection had something to remove
