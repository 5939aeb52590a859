r"""Projected areas of lattices and of their unit-cell apertures (paper Fig. 3G, Fig. 5).

The area of a closed loop of nodes is the shoelace area of the polygon through them, projected
on the loop's best-fit plane (PCA):

.. math:: A = \tfrac12 \left|\sum_j (x_j y_{j+1} - x_{j+1} y_j)\right| \quad (\mathrm{mm}^2).

A self-intersecting loop gets its signed-area sum (lobes of opposite orientation cancel).

Square sinusoidal lattices: branch nodes ``0 .. n²-1`` in row-major order,
node ``k = n i + j`` at ``(l i, l j, 0)``; every lattice edge is a chain of node indices from one
branch node to a neighbouring one, ghost nodes in between (both end nodes included).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.analysis._validate import as_index, as_points
from rotomorph.errors import InvalidParameterError

__all__ = [
    "lattice_boundary_loop",
    "loop_area",
    "normalized_area",
    "polygon_area",
    "unit_apertures",
    "unit_cell_loops",
]


def polygon_area(points: FloatArray) -> float:
    """Area of the closed polygon through ``points``, projected on their best-fit plane (mm²).

    Parameters
    ----------
    points
        Vertices ``(M, 3)`` in order around the loop (mm); the closing edge is implied.

    Returns
    -------
    float
        Non-negative area; 0.0 for fewer than 3 vertices or collinear vertices.
    """
    pts = as_points(points, "points")
    if len(pts) < 3:
        return 0.0
    x = pts - pts.mean(axis=0)
    _, sv, vt = np.linalg.svd(x, full_matrices=False)
    if sv[1] <= 1e-12 * max(sv[0], 1e-300):
        return 0.0
    p = x @ vt[:2].T
    xs, ys = p[:, 0], p[:, 1]
    twice = np.dot(xs, np.roll(ys, -1)) - np.dot(np.roll(xs, -1), ys)
    return float(0.5 * abs(twice))


def loop_area(positions: FloatArray, loop: IntArray) -> float:
    """Projected area (mm²) of the loop of node indices ``loop`` at ``positions`` ``(N, 3)``."""
    pos = as_points(positions, "positions")
    idx = as_index(loop, "loop", len(pos))
    return polygon_area(pos[idx])


def normalized_area(positions: FloatArray, reference: FloatArray, loop: IntArray) -> float:
    """Projected area of ``loop`` at ``positions`` over its area at ``reference`` (A/A₀).

    Parameters
    ----------
    positions
        Current node positions ``(N, 3)`` (mm).
    reference
        Reference (printed) node positions ``(N, 3)`` (mm).
    loop
        Node indices around the lattice boundary (e.g. :func:`lattice_boundary_loop`).

    Raises
    ------
    InvalidParameterError
        If the reference area is zero.
    """
    a0 = loop_area(reference, loop)
    if a0 == 0.0:
        raise InvalidParameterError("reference", "the loop encloses no area in the reference")
    return loop_area(positions, loop) / a0


def _chain_lookup(edge_chains: Sequence[IntArray]) -> dict[tuple[int, int], IntArray]:
    lookup: dict[tuple[int, int], IntArray] = {}
    for k, chain in enumerate(edge_chains):
        c = np.asarray(chain)
        if c.ndim != 1 or len(c) < 2 or not np.issubdtype(c.dtype, np.integer):
            raise InvalidParameterError(
                f"edge_chains[{k}]", "must be a 1-D array of at least two node indices"
            )
        c = c.astype(np.int64)
        lookup[(int(c[0]), int(c[-1]))] = c
        lookup[(int(c[-1]), int(c[0]))] = c[::-1]
    return lookup


def _walk(branch_loop: list[int], lookup: dict[tuple[int, int], IntArray]) -> IntArray:
    parts = []
    for a, b in zip(branch_loop, branch_loop[1:] + branch_loop[:1], strict=True):
        chain = lookup.get((a, b))
        if chain is None:
            raise InvalidParameterError(
                "edge_chains",
                f"no chain joins branch nodes {a} and {b}; chains must run from one branch node "
                "to a neighbouring one with both end nodes included",
            )
        parts.append(chain[:-1])
    return np.concatenate(parts)


def _check_grid(n: int) -> int:
    if int(n) != n or n < 2:
        raise InvalidParameterError("n", f"branch grid size must be an integer >= 2; got {n}")
    return int(n)


def lattice_boundary_loop(edge_chains: Sequence[IntArray], n: int) -> IntArray:
    """Node indices around the boundary of an ``n × n`` square lattice, counter-clockwise.

    Parameters
    ----------
    edge_chains
        One node-index array per lattice edge, end (branch) nodes included, either direction.
    n
        Number of branch nodes per side (``n >= 2``); branch node ``n i + j`` sits at
        ``(l i, l j)``.

    Returns
    -------
    ndarray
        Branch and ghost node indices around the boundary, starting at node 0, without
        repeating it; counter-clockwise seen from +z in the printed state.

    Raises
    ------
    InvalidParameterError
        If a boundary edge has no chain.
    """
    n = _check_grid(n)
    lookup = _chain_lookup(edge_chains)
    corners = (
        [n * i for i in range(n)]  # j = 0, along +x
        + [n * (n - 1) + j for j in range(1, n)]  # i = n-1, along +y
        + [n * i + n - 1 for i in range(n - 2, -1, -1)]  # j = n-1, along -x
        + [j for j in range(n - 2, 0, -1)]  # i = 0, along -y
    )
    return _walk(corners, lookup)


def unit_cell_loops(edge_chains: Sequence[IntArray], n: int) -> list[IntArray]:
    """Node-index loops of the ``(n-1)²`` unit cells, counter-clockwise, cell ``(n-1) i + j``.

    Cell ``(i, j)`` is bounded by branch nodes ``(i, j), (i+1, j), (i+1, j+1), (i, j+1)``; see
    :func:`lattice_boundary_loop` for the conventions.
    """
    n = _check_grid(n)
    lookup = _chain_lookup(edge_chains)
    loops = []
    for i in range(n - 1):
        for j in range(n - 1):
            k = n * i + j
            loops.append(_walk([k, k + n, k + n + 1, k + 1], lookup))
    return loops


def unit_apertures(positions: FloatArray, edge_chains: Sequence[IntArray], n: int) -> list[float]:
    """Projected area of every unit cell's loop (mm²), cell ``(n-1) i + j`` at index ``c``.

    Each loop is projected on its own best-fit plane, so curved lattices report each
    aperture's own opening.
    """
    pos = as_points(positions, "positions")
    return [loop_area(pos, loop) for loop in unit_cell_loops(edge_chains, n)]
