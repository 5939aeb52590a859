"""Sparsity pattern of a rod network's reduced Hessian and where each stencil block lands in it.

The Hessian couples the 11 degrees of freedom of every bend-twist stencil
``[x0, θe, x1, θf, x2]`` and the 6 of every stretching edge ``[xa, xb]``. Listing every one of
those ``121 S + 36 E`` couplings and sorting them (the obvious way) costs a sort of 35 million
keys for a 100 × 100 lattice. The couplings come in blocks instead: a node's three coordinates
and an edge's twist angle are *units* (3 and 1 degrees of freedom, contiguous in the
node-interleaved layout of :class:`rotomorph.rod.stencils.DofLayout`), and two units are either
coupled in every component or not at all. So the pattern is found on unit pairs (``25 S + 4 E``
keys, five times fewer) and expanded: column c of unit C holds, for every unit R coupled to C
in increasing order, the free degrees of freedom of R.

The result is the same compressed-sparse-column pattern (rows sorted within each column) and the
same slot arrays as sorting all couplings, with fixed degrees of freedom removed.
"""

from __future__ import annotations

import numpy as np

from rotomorph._typing import IntArray

#: Unit (0..4) of each of the 11 stencil degrees of freedom ``[x0, θe, x1, θf, x2]``.
_STENCIL_UNIT = np.array([0, 0, 0, 1, 2, 2, 2, 3, 4, 4, 4])
#: Unit (0..1) of each of the 6 edge degrees of freedom ``[xa, xb]``.
_EDGE_UNIT = np.array([0, 0, 0, 1, 1, 1])


def _unit_first(dofs: IntArray, unit_of: IntArray) -> IntArray:
    """First degree of freedom of each unit of each block ``(B, units)``."""
    first = np.searchsorted(unit_of, np.arange(unit_of.max() + 1))
    return dofs[:, first]


def hessian_pattern(
    stencil_dofs: IntArray, edge_dofs: IntArray, reduced: IntArray
) -> tuple[IntArray, IntArray, tuple[IntArray, IntArray]]:
    """Slots of every stencil and edge Hessian entry in the reduced CSC pattern, and the pattern.

    Parameters
    ----------
    stencil_dofs
        ``(S, 11)`` global degrees of freedom of the stencils (:meth:`DofLayout.stencil_dofs`).
    edge_dofs
        ``(E, 6)`` global degrees of freedom of the edges (:meth:`DofLayout.edge_dofs`).
    reduced
        ``(n_dof,)`` index of each global degree of freedom among the free ones, −1 if fixed
        (increasing along the free ones).

    Returns
    -------
    stencil_slots, edge_slots, (indices, indptr)
        ``(S, 11, 11)`` and ``(E, 6, 6)`` position in the CSC data array of entry
        ``[row a, column b]`` of each block (−1 where the row or column is fixed), and the CSC
        row indices (int32, sorted within each column) and column pointers (int32).
    """
    n_dof = len(reduced)
    is_free = reduced >= 0
    cum_free = np.concatenate([[0], np.cumsum(is_free)])
    kinds = ((stencil_dofs, _STENCIL_UNIT), (edge_dofs, _EDGE_UNIT))
    firsts = [_unit_first(dofs, unit_of) for dofs, unit_of in kinds]
    # units by their first degree of freedom (a node's coordinates: 3, an edge's twist: 1)
    size = np.zeros(n_dof, dtype=np.int64)
    covered = np.zeros(n_dof, dtype=bool)
    for (dofs, unit_of), first in zip(kinds, firsts, strict=True):
        size[first.ravel()] = np.tile(np.bincount(unit_of), len(dofs))
        covered[dofs.ravel()] = True
    unit_start = np.maximum.accumulate(np.where(size > 0, np.arange(n_dof), 0))
    unit_free = cum_free[np.minimum(np.arange(n_dof) + size, n_dof)] - cum_free[:-1]
    # coupled unit pairs, key = column unit * n_dof + row unit, sorted
    keys = [(u[:, None, :] * n_dof + u[:, :, None]).ravel() for u in firsts]
    pairs, inverse = np.unique(np.concatenate(keys), return_inverse=True)
    col_unit, row_unit = np.divmod(pairs, n_dof)
    # a column of unit C lists the free rows of every unit coupled to C, in increasing order
    rows_here = unit_free[row_unit]
    cum_rows = np.concatenate([[0], np.cumsum(rows_here)])
    group_first = np.searchsorted(col_unit, col_unit, side="left")
    offset = cum_rows[:-1] - cum_rows[group_first]  # of each row unit within its column's list
    cols = np.flatnonzero(np.diff(np.concatenate([[-1], col_unit])) != 0)  # first pair per C
    length = np.zeros(n_dof, dtype=np.int64)
    list_start = np.zeros(n_dof, dtype=np.int64)
    length[col_unit[cols]] = np.diff(np.concatenate([cum_rows[cols], [cum_rows[-1]]]))
    list_start[col_unit[cols]] = cum_rows[cols]
    sizes = size[row_unit]
    member = np.repeat(row_unit - np.cumsum(sizes) + sizes, sizes) + np.arange(sizes.sum())
    row_list = reduced[member]
    row_list = row_list[row_list >= 0]
    free_cols = np.flatnonzero(is_free)
    lens = np.where(covered[free_cols], length[unit_start[free_cols]], 0)
    indptr = np.concatenate([[0], np.cumsum(lens)])
    within = np.arange(int(indptr[-1])) - np.repeat(indptr[:-1], lens)
    indices = row_list[np.repeat(list_start[unit_start[free_cols]], lens) + within]
    # slot of entry (row a, column b) of each block: column start + offset of a's unit in b's
    # column + position of a among its unit's free dofs (computed per block, then broadcast)
    local_free = cum_free[:-1] - cum_free[unit_start]
    col_start = np.concatenate([indptr[:-1], [0]])[reduced]  # reduced -1 -> unused entry
    out = []
    stop = 0
    for (dofs, unit_of), key in zip(kinds, keys, strict=True):
        n_units = int(unit_of.max()) + 1
        pair = inverse[stop : stop + key.size].reshape(len(dofs), n_units, n_units)
        stop += key.size
        slot = offset[pair][:, unit_of[:, None], unit_of[None, :]]
        slot += col_start[dofs][:, None, :]
        slot += local_free[dofs][:, :, None]
        free_dof = is_free[dofs]
        slot[~(free_dof[:, :, None] & free_dof[:, None, :])] = -1
        out.append(slot)
    return out[0], out[1], (indices.astype(np.int32), indptr.astype(np.int32))
