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


@numba.njit(cache=True)
def _rotate(v: FloatArray, axis: FloatArray, angle: float) -> FloatArray:  # pragma: no cover
    """Rotate ``v`` about the unit ``axis`` by ``angle`` (Rodrigues)."""
    c, s = np.cos(angle), np.sin(angle)
    cr = np.array(
        [
            axis[1] * v[2] - axis[2] * v[1],
            axis[2] * v[0] - axis[0] * v[2],
            axis[0] * v[1] - axis[1] * v[0],
        ]
    )
    return v * c + cr * s + axis * (axis[0] * v[0] + axis[1] * v[1] + axis[2] * v[2]) * (1.0 - c)


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
    out[0] = start
    out[1] = start + rest[0] * t
    for i in range(n - 2):
        m2 = np.array(
            [t[1] * m1[2] - t[2] * m1[1], t[2] * m1[0] - t[0] * m1[2], t[0] * m1[1] - t[1] * m1[0]]
        )
        c, s = np.cos(tw[i]), np.sin(tw[i])
        # [[-s, 1 + c], [-(1 + c), -s]] a = 2 (k1, k2); determinant 2 + 2c
        det = s * s + (1.0 + c) * (1.0 + c)
        b1, b2 = 2.0 * k1[i], 2.0 * k2[i]
        a1 = (-s * b1 - (1.0 + c) * b2) / det
        a2 = ((1.0 + c) * b1 - s * b2) / det
        kb = a1 * m1 + a2 * m2
        size = np.sqrt(kb[0] ** 2 + kb[1] ** 2 + kb[2] ** 2)
        if size > 0.0:
            axis = kb / size
            beta = 2.0 * np.arctan(0.5 * size)
            t = _rotate(t, axis, beta)
            m1 = _rotate(m1, axis, beta)
        m1 = _rotate(m1, t, tw[i])
        t = t / np.sqrt(t[0] ** 2 + t[1] ** 2 + t[2] ** 2)
        m1 = m1 - (m1[0] * t[0] + m1[1] * t[1] + m1[2] * t[2]) * t
        m1 = m1 / np.sqrt(m1[0] ** 2 + m1[1] ** 2 + m1[2] ** 2)
        out[i + 2] = out[i + 1] + rest[i + 1] * t
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


def min_clearance(points: FloatArray, *, exclude_arc: float) -> float:
    """Smallest distance (mm) between two vertices more than ``exclude_arc`` apart along the
    curve (neighbours along the filament are always close and do not count).

    A value below the filament diameter means the free shape passes through itself (no contact
    model); the caller flags it. Use ``exclude_arc`` ≳ 2 diameters.
    """
    x = np.asarray(points, dtype=float)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(x, axis=0), axis=1))])
    d = np.linalg.norm(x[:, None, :] - x[None, :, :], axis=-1)
    far = np.abs(s[:, None] - s[None, :]) > exclude_arc
    return float(d[far].min()) if np.any(far) else float("inf")
