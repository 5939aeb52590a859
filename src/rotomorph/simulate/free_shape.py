r"""Zero-energy equilibrium of a free filament, built directly from its natural strains.

A free rod (no supports, loads, gravity or contact) can always reach zero elastic energy: its
equilibrium is the curve whose discrete strains equal the natural ones, whatever the
stiffnesses (Kirchhoff rods: Love, *A Treatise on the Mathematical Theory of Elasticity*, §252;
discrete elastic rods: Bergou et al., ACM TOG 27, 63 (2008)). For a chain this curve is built
edge by edge, exactly for the discrete strains of :func:`rotomorph.geometry.pair_strains`:

with k_b = 2 t_e × t_f/(1 + t_e·t_f) the curvature binormal and m1, m2 the material directors,
κ1 = ½ k_b·(m2_e + m2_f), κ2 = −½ k_b·(m1_e + m1_f), and m1_f the parallel transport of m1_e
turned by the twist τ about t_f. Writing k_b = a1 m1_e + a2 m2_e (k_b ⟂ t_e), parallel
transport keeps k_b, so::

    2 κ1 = (1 + cos τ) a2 − sin τ a1,   2 κ2 = −(1 + cos τ) a1 − sin τ a2,

a linear 2 × 2 system (determinant 2 + 2 cos τ > 0 for abs(τ) < π). Then the norm of k_b,
2 tan(β/2), gives
the turning angle β about k_b, and the next edge has the natural (rest) length.

This is the state the Newton solver of :func:`rotomorph.simulate.filament.simulate_filament`
converges to for the same model (a test checks it), obtained without iterations: the paper
report uses it for free filaments so that every number can be recomputed at two resolutions
and for every calibration sample in milliseconds. Self-contact is not resolved (neither does the
rod solver without a contact model): :func:`min_clearance` reports it.
"""

from __future__ import annotations

from typing import Any

import numba
import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidDesignError

__all__ = ["free_equilibrium", "min_clearance"]


# Scalar code on purpose: array expressions and row assignments (``out[i] = v``) make numba
# compile shape checks with formatted error messages, which cost ~10 s of compilation on the
# first run; component-wise code does the same arithmetic in the same order and compiles in ~1 s.


@numba.njit(cache=True)
def _rotate(
    v0: float, v1: float, v2: float, a0: float, a1: float, a2: float, angle: float
) -> tuple[float, float, float]:  # pragma: no cover - compiled
    """Rotate ``v`` about the unit axis ``a`` by ``angle`` (Rodrigues)."""
    c, s = np.cos(angle), np.sin(angle)
    d, e = a0 * v0 + a1 * v1 + a2 * v2, 1.0 - c
    return (
        v0 * c + (a1 * v2 - a2 * v1) * s + a0 * d * e,
        v1 * c + (a2 * v0 - a0 * v2) * s + a1 * d * e,
        v2 * c + (a0 * v1 - a1 * v0) * s + a2 * d * e,
    )


@numba.njit(cache=True)
def _build(
    start: FloatArray,
    t: FloatArray,
    m1: FloatArray,
    k1: FloatArray,
    k2: FloatArray,
    tw: FloatArray,
    rest: FloatArray,
) -> FloatArray:  # pragma: no cover - compiled
    n = len(rest) + 1
    out = np.empty((n, 3))
    t0, t1, t2 = t[0], t[1], t[2]
    p0, p1, p2 = m1[0], m1[1], m1[2]
    for k in range(3):
        out[0, k] = start[k]
        out[1, k] = start[k] + rest[0] * t[k]
    for i in range(n - 2):
        q0, q1, q2 = t1 * p2 - t2 * p1, t2 * p0 - t0 * p2, t0 * p1 - t1 * p0  # m2 = t x m1
        c, s = np.cos(tw[i]), np.sin(tw[i])
        # [[-s, 1 + c], [-(1 + c), -s]] a = 2 (k1, k2); determinant 2 + 2c
        det = s * s + (1.0 + c) * (1.0 + c)
        b1, b2 = 2.0 * k1[i], 2.0 * k2[i]
        a1 = (-s * b1 - (1.0 + c) * b2) / det
        a2 = ((1.0 + c) * b1 - s * b2) / det
        kb0, kb1, kb2 = a1 * p0 + a2 * q0, a1 * p1 + a2 * q1, a1 * p2 + a2 * q2
        size = np.sqrt(kb0**2 + kb1**2 + kb2**2)
        if size > 0.0:
            x0, x1, x2 = kb0 / size, kb1 / size, kb2 / size
            beta = 2.0 * np.arctan(0.5 * size)
            t0, t1, t2 = _rotate(t0, t1, t2, x0, x1, x2, beta)
            p0, p1, p2 = _rotate(p0, p1, p2, x0, x1, x2, beta)
        p0, p1, p2 = _rotate(p0, p1, p2, t0, t1, t2, tw[i])
        norm = np.sqrt(t0**2 + t1**2 + t2**2)
        t0, t1, t2 = t0 / norm, t1 / norm, t2 / norm
        d = p0 * t0 + p1 * t1 + p2 * t2
        p0, p1, p2 = p0 - d * t0, p1 - d * t1, p2 - d * t2
        norm = np.sqrt(p0**2 + p1**2 + p2**2)
        p0, p1, p2 = p0 / norm, p1 / norm, p2 / norm
        out[i + 2, 0] = out[i + 1, 0] + rest[i + 1] * t0
        out[i + 2, 1] = out[i + 1, 1] + rest[i + 1] * t1
        out[i + 2, 2] = out[i + 1, 2] + rest[i + 1] * t2
    return out


def free_equilibrium(model: object) -> FloatArray:
    """Vertices ``(N, 3)`` (mm) of the zero-energy shape of a free chain ``model``.

    Parameters
    ----------
    model
        A :class:`rotomorph.rod.model.Model` whose network is one open chain (nodes in order);
        its ``integrated_natural()``, ``rest_length`` and reference first edge and director are
        used (the result is placed with the printed first edge; rigid motions are free).

    Raises
    ------
    InvalidDesignError
        The network is not a single open chain, or a natural twist reaches ±π per vertex.
    """
    net = model.network  # type: ignore[attr-defined]
    edges = np.asarray(net.edges)
    n = len(net.nodes)
    if len(edges) != n - 1 or not np.array_equal(
        edges, np.column_stack([np.arange(n - 1), np.arange(1, n)])
    ):
        raise InvalidDesignError("free_equilibrium.model", "needs one open chain of nodes")
    k1, k2, tw = model.integrated_natural()  # type: ignore[attr-defined]
    if np.any(np.abs(tw) >= np.pi - 1e-9):
        raise InvalidDesignError(
            "free_equilibrium.model", "natural twist per vertex must be < pi; refine the spacing"
        )
    mod: Any = model
    rest = np.asarray(mod.rest_length, dtype=float)
    x0 = np.asarray(net.nodes, dtype=float)
    t = x0[1] - x0[0]
    t = t / np.linalg.norm(t)
    m1 = np.asarray(mod.directors, dtype=float)[0]
    m1 = m1 - np.dot(m1, t) * t
    m1 = m1 / np.linalg.norm(m1)
    f = np.ascontiguousarray
    return _build(  # type: ignore[no-any-return]
        f(x0[0]), f(t), f(m1), f(k1, dtype=float), f(k2, dtype=float), f(tw, dtype=float), f(rest)
    )


_CLEARANCE_BLOCK = 128  # rows of the distance matrix at once (memory: 128 × N doubles)


def min_clearance(points: FloatArray, *, exclude_arc: float) -> float:
    """Smallest distance (mm) between two vertices more than ``exclude_arc`` apart along the
    curve (neighbours along the filament are always close and do not count).

    A value below the filament diameter means the free shape passes through itself (no contact
    model); the caller flags it. Use ``exclude_arc`` ≳ 2 diameters.
    """
    x = np.asarray(points, dtype=float)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    # arc length grows along the curve: the vertices far from i are j >= first[i] (and those
    # before i, the same pairs seen from the other end)
    first = np.searchsorted(s, s + exclude_arc, side="right")
    rows = np.flatnonzero(first < len(x))
    if rows.size == 0:
        return float("inf")
    c = x - x.mean(axis=0)  # squared distances as |a|² + |b|² - 2 a·b, about the centroid
    sq = np.einsum("ij,ij->i", c, c)
    best, pair = np.inf, (0, 0)
    for a in range(0, rows.size, _CLEARANCE_BLOCK):
        i = rows[a : a + _CLEARANCE_BLOCK]
        j0 = int(first[i].min())
        d2 = sq[i, None] + sq[None, j0:] - 2.0 * (c[i] @ c[j0:].T)
        d2[np.arange(j0, len(x))[None, :] < first[i][:, None]] = np.inf
        k = int(np.argmin(d2))
        if d2.flat[k] < best:
            best, pair = float(d2.flat[k]), (int(i[k // d2.shape[1]]), j0 + k % d2.shape[1])
    # the closest pair's distance itself (the expansion above only picks the pair)
    return float(np.linalg.norm(x[pair[0]] - x[pair[1]]))
