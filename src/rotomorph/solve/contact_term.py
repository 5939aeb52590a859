"""Contact composed into the rod objective: the barrier on the free DOFs and its step bound.

The rod objective adds :class:`ContactTerm`'s energy, gradient and Hessian to its own, so the
Newton step, the line search (the merit function is the total energy) and the Hessian stay
consistent. Two more duties:

* **step bound**: the largest fraction of a Newton step that is provably free of contact
  (the objective's ``max_step``), and a check that the straight path from the last accepted
  iterate to a line-search trial point is free of contact (a trial that fails it has infinite
  energy), so no accepted iterate can tunnel through a filament;
* **rigid motions on a floor**: a free body resting on a frictionless floor keeps only the
  three rigid motions tangent to the floor (two translations, the rotation about the normal),
  which are removed from every step instead of all six.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from numba import njit, types
from numba.typed import Dict

from rotomorph._typing import FloatArray, IntArray
from rotomorph.contact.potential import Contact, ContactPotential, HessianBlocks
from rotomorph.contact.stacked import WIDTH, DofBlocks, StackedContact
from rotomorph.design.network import Network
from rotomorph.solve.linalg import BandedMatrix, SparseMatrix
from rotomorph.solve.sparse_cholesky import Symbolic, analyse_pattern

__all__ = ["ContactTerm", "HessianPattern", "banded_to_csc"]

_QUAD = types.UniTuple(types.int64, 4)
_SQUARE = WIDTH * WIDTH
_NO_QUADS = np.zeros((0, 4), dtype=np.int64)
_NO_PAIR = np.zeros((0, 12, 12))
_NO_KEYS = np.zeros(0, dtype=np.int64)

#: factor growth (nonzeros of L relative to the last fresh ordering) that triggers a new one
REORDER = 1.3


class HessianPattern:
    """Sparsity pattern of rod plus contact Hessians that only grows, with its analysis.

    Contacts come and go between Newton iterations; re-analysing the sparse pattern each time
    would cost more than the factorization. The pattern is the union of the rod's and every
    contact block seen so far (explicit zeros where a contact is not active now); it is
    re-analysed only when a new block appears. One pattern serves every solve on the same
    network and free DOFs (the steps of a heating ramp), so a contact that recurs from one step
    to the next costs no new analysis.
    """

    def __init__(self) -> None:
        self.analyses = 0  # symbolic analyses (the pattern grew)
        self.orderings = 0  # of which with a new fill-reducing ordering
        self._ordered_nnz = 0
        self._reset(-1)

    def _reset(self, n: int) -> None:
        self._n = n
        self._union: tuple[np.ndarray, np.ndarray] | None = None  # CSC indices, indptr
        self._keys: IntArray = np.zeros(0, dtype=np.int64)
        self._base: tuple[IntArray, IntArray] | None = None  # the base's indptr, indices
        self._base_pos: IntArray = np.zeros(0, dtype=np.int64)
        self._sym: Symbolic | None = None
        self._forget_positions()

    def _forget_positions(self) -> None:
        """Empty the remembered data positions of pair blocks (the union changed)."""
        # the same for the blocks of a stacked contact (generalised coordinates), by block key
        self._dof_slot_of = Dict.empty(key_type=types.int64, value_type=types.int64)
        self._dof_slots: IntArray = np.empty((0, _SQUARE), dtype=np.int64)
        self._dof_used = np.zeros(1, dtype=np.int64)
        # pair (node indices) -> row of self._slots: the data position of each of its 144
        # entries in the loop order of _scatter_blocks (-1: not a free coordinate, -2: not in
        # the pattern)
        self._slot_of = Dict.empty(key_type=_QUAD, value_type=types.int64)
        self._slots: IntArray = np.empty((0, 144), dtype=np.int64)
        self._slot_quads: IntArray = np.empty((0, 4), dtype=np.int64)  # the pair of each row
        self._used = np.zeros(1, dtype=np.int64)
        self._slot_coords: IntArray | None = None  # the coord_reduced they hold for
        self._slot_nodes = -1  # and the number of network nodes (quads beyond: obstacles)

    def add(
        self, base: sp.csc_matrix, contact: HessianBlocks | DofBlocks, coord_reduced: IntArray
    ) -> SparseMatrix | None:
        """``base + contact`` (``n x n``) on the grown pattern; ``coord_reduced`` maps a node
        coordinate ``3 i + k`` (and, for the :class:`~rotomorph.contact.stacked.DofBlocks` of a
        stacked contact, the twist angle ``3 N + e``) to its free index (-1: fixed). None when
        the contact blocks have no non-zero entry on free coordinates."""
        n = base.shape[0]
        if self._n != n:
            self._reset(n)
        base = base.tocsc()
        if not self._known_base(base):  # (the known base is sorted: no need to check that)
            if not base.has_sorted_indices:
                base = base.sorted_indices()
            if not self._known_base(base):
                self._grow(base, np.zeros(0, dtype=np.int64), n, base_known=False)
        assert self._union is not None
        cdata = np.zeros(len(self._keys))
        if isinstance(contact, DofBlocks):
            count = self._scatter_dofs(coord_reduced, contact, cdata)
            if count < 0:  # a coupling the pattern does not hold yet: grow by all of them
                keys = np.empty(_SQUARE * len(contact.keys), dtype=np.int64)
                found = _dof_keys(
                    n, coord_reduced, contact.dofs, np.ascontiguousarray(contact.blocks), keys
                )
                self._grow(base, np.unique(keys[:found]), n, base_known=True)
                cdata = np.zeros(len(self._keys))
                count = self._scatter_dofs(coord_reduced, contact, cdata)
        else:
            count = self._scatter(coord_reduced, contact, cdata)
            if count < 0:  # a coupling the pattern does not hold yet: grow by all of them
                blocks = (contact.n_nodes, contact.quads, contact.pair, contact.nodes, contact.node)
                keys = np.empty(144 * len(contact.quads) + 9 * len(contact.nodes), dtype=np.int64)
                found = _scatter_blocks(*self._union[::-1], coord_reduced, *blocks, cdata, keys)
                self._grow(base, np.unique(keys[:found]), n, base_known=True)
                cdata = np.zeros(len(self._keys))
                count = self._scatter(coord_reduced, contact, cdata)
        if count == 0:
            return None
        data = cdata
        _add_at(data, self._base_pos, base.data)  # data[pos] += base.data, compiled
        assert self._sym is not None
        indices, indptr = self._union
        return SparseMatrix.from_arrays(data, indices, indptr, self._sym)

    def _known_base(self, base: sp.csc_matrix) -> bool:
        """Whether ``base`` has the pattern of the base the union was last grown with."""
        known = self._base
        return (
            self._union is not None
            and known is not None
            and np.array_equal(known[0], base.indptr)
            and np.array_equal(known[1], base.indices)
        )

    def _scatter(self, coord_reduced: IntArray, contact: HessianBlocks, out: FloatArray) -> int:
        """:func:`_scatter_blocks` into ``out``, the pair blocks through the remembered data
        positions of their entries (found once per pair and pattern, not per entry and call);
        the same additions in the same order."""
        assert self._union is not None
        indices, indptr = self._union
        if (
            self._slot_coords is None
            or self._slot_nodes != contact.n_nodes
            or not np.array_equal(self._slot_coords, coord_reduced)
        ):
            self._forget_positions()
            self._slot_coords = coord_reduced.copy()
            self._slot_nodes = contact.n_nodes
        need = int(self._used[0]) + len(contact.quads)
        if need > len(self._slots):
            rows = max(need, 2 * len(self._slots), 64)
            grown = np.empty((rows, 144), dtype=np.int64)
            grown[: len(self._slots)] = self._slots
            self._slots = grown
            grown_quads = np.empty((rows, 4), dtype=np.int64)
            grown_quads[: len(self._slot_quads)] = self._slot_quads
            self._slot_quads = grown_quads
        count = _scatter_pairs(
            indptr, indices, coord_reduced, contact.n_nodes, contact.quads, contact.pair, out,
            self._slot_of, self._slots, self._slot_quads, self._used,
        )  # fmt: skip
        if count < 0 or not len(contact.nodes):
            return count
        floor = _scatter_blocks(
            indptr, indices, coord_reduced, contact.n_nodes, _NO_QUADS, _NO_PAIR,
            contact.nodes, contact.node, out, _NO_KEYS,
        )  # fmt: skip
        return -1 if floor < 0 else count + floor

    def _scatter_dofs(self, coord_reduced: IntArray, contact: DofBlocks, out: FloatArray) -> int:
        """The blocks of a stacked contact into ``out`` through remembered data positions
        (found once per block key and pattern); -1 when an entry is not in the pattern."""
        assert self._union is not None
        indices, indptr = self._union
        if (
            self._slot_coords is None
            or self._slot_nodes != contact.n_nodes
            or not np.array_equal(self._slot_coords, coord_reduced)
        ):
            self._forget_positions()
            self._slot_coords = coord_reduced.copy()
            self._slot_nodes = contact.n_nodes
        need = int(self._dof_used[0]) + len(contact.keys)
        if need > len(self._dof_slots):
            rows = max(need, 2 * len(self._dof_slots), 64)
            grown = np.empty((rows, _SQUARE), dtype=np.int64)
            grown[: len(self._dof_slots)] = self._dof_slots
            self._dof_slots = grown
        return int(
            _scatter_dof_blocks(
                indptr, indices, coord_reduced, contact.dofs,
                np.ascontiguousarray(contact.blocks), contact.keys, out, self._dof_slot_of,
                self._dof_slots, self._dof_used,
            )
        )  # fmt: skip

    def _grow(self, base: sp.csc_matrix, ckeys: IntArray, n: int, base_known: bool) -> None:
        """Add the keys ``column * n + row`` of ``base`` (unless ``base_known``: its pattern is
        the one the union holds) and the sorted distinct ``ckeys`` to the union, then
        re-analyse it. The new keys are inserted into the sorted arrays, and every stored
        position (the base's, the remembered pair blocks') moves by the number of keys
        inserted before it: the same arrays as merging and sorting afresh."""
        keys = self._keys
        last = max(len(keys) - 1, 0)
        sources = [ckeys]
        if not base_known:
            bcol = np.repeat(np.arange(n, dtype=np.int64), np.diff(base.indptr))
            bkeys = bcol * n + base.indices
            sources.append(bkeys)
        missing = [
            add if not len(keys) else add[keys[np.minimum(np.searchsorted(keys, add), last)] != add]
            for add in sources
        ]
        new = np.unique(np.concatenate(missing))
        ins = np.searchsorted(keys, new)
        # old position q moves to q + shift[q]
        shift = np.cumsum(np.bincount(ins, minlength=len(keys) + 1))
        if not base_known:
            self._base = (base.indptr.copy(), base.indices.copy())
            self._base_pos = np.searchsorted(np.insert(keys, ins, new), bkeys)
        elif len(new):
            self._base_pos = self._base_pos + shift[self._base_pos]
        if self._union is not None and not len(new):
            return  # nothing new (the base's stored entries changed, not the union)
        rows_old, indptr_old = self._union or (
            np.zeros(0, dtype=np.int32),
            np.zeros(n + 1, dtype=np.int32),
        )
        rows = np.insert(rows_old, ins, (new % n).astype(np.int32))
        indptr = indptr_old + np.searchsorted(new // n, np.arange(n + 1)).astype(np.int32)
        self._union = (rows, indptr)
        self._keys = np.insert(keys, ins, new)
        if self._slot_coords is not None and len(keys):
            _move_slots(
                self._slots, self._slot_quads, int(self._used[0]), shift, self._slot_coords,
                self._slot_nodes, indptr, rows,
            )  # fmt: skip
            # the stacked contact's blocks find their positions again (a growth is rare)
            self._dof_slot_of = Dict.empty(key_type=types.int64, value_type=types.int64)
            self._dof_used[0] = 0
        else:
            self._forget_positions()
        # keep the ordering while the factor stays within REORDER of its size when ordered;
        # a new minimum-degree ordering costs more than the numeric factorization
        sym = None if self._sym is None else analyse_pattern(indptr, rows, self._sym.perm)
        if sym is None or sym.lp[-1] > REORDER * self._ordered_nnz:
            sym = analyse_pattern(indptr, rows)
            self._ordered_nnz = int(sym.lp[-1])
            self.orderings += 1
        self._sym = sym
        self.analyses += 1


class ContactTerm:
    """A :class:`ContactPotential` seen through a rod objective's DOF layout.

    Parameters
    ----------
    contact
        Settings.
    network
        The printed network.
    pos_dof
        Layout index of each node's x coordinate ``(N,)`` (y, z follow).
    reduced
        Reduced (free) index of every layout DOF, -1 where fixed ``(ndof,)``.
    force_scale
        Typical nodal force (N) for the default barrier stiffness.
    pattern
        The grown sparsity pattern to start from and to update (a :class:`HessianPattern`
        shared by the solves of one network and support set, e.g. the steps of a ramp);
        default: a new one.
    theta_dof, directors
        With a stacked contact (``contact.stack`` of more than one layer): layout index of each
        segment's twist angle ``(E,)`` and the printed material directors m1 ``(E, 3)``; the
        contact then depends on the twist angles too
        (:class:`~rotomorph.contact.stacked.StackedContact`).
    """

    def __init__(
        self,
        contact: Contact,
        network: Network,
        pos_dof: IntArray,
        reduced: IntArray,
        force_scale: float,
        pattern: HessianPattern | None = None,
        theta_dof: IntArray | None = None,
        directors: FloatArray | None = None,
    ) -> None:
        coord = (pos_dof[:, None] + np.arange(3)).ravel()
        self.stacked = not contact.stack.is_single
        self.potential: ContactPotential | StackedContact
        if self.stacked:
            if theta_dof is None or directors is None:
                raise ValueError("a stacked contact needs the twist angles and directors")
            self.potential = StackedContact(contact, network, directors, force_scale)
            coord = np.concatenate([coord, np.asarray(theta_dof, dtype=np.int64)])
        else:
            self.potential = ContactPotential(contact, network, force_scale=force_scale)
        # node coordinate 3i+k (and, stacked, twist angle 3N+e) -> reduced index or -1
        self._coord_reduced = np.ascontiguousarray(reduced[coord], dtype=np.int64)
        self._nfree = int((reduced >= 0).sum())
        self.pattern = HessianPattern() if pattern is None else pattern

    # ------------------------------------------------------------------ energy
    def evaluate(
        self,
        pos: FloatArray,
        need_grad: bool,
        need_hess: int,
        frames: tuple[FloatArray, FloatArray, FloatArray] | None = None,
    ) -> tuple[float, FloatArray | None, FloatArray | None, HessianBlocks | DofBlocks | None]:
        """Energy, gradient on node coordinates ``(3N,)`` and on the twist angles ``(E,)``
        (None without a stacked contact) and the Hessian's local blocks. ``frames``:
        ``(t, m1, m2)`` of the configuration, needed by a stacked contact."""
        if isinstance(self.potential, StackedContact):
            assert frames is not None
            e, gx, gth, dblocks = self.potential.evaluate_blocks(pos, frames, need_grad, need_hess)
            if not np.isfinite(e):
                return np.inf, None, None, None
            return e, (None if gx is None else gx.ravel()), gth, dblocks
        e, g, blocks = self.potential.evaluate_blocks(pos, need_grad, need_hess)
        if not np.isfinite(e):
            return np.inf, None, None, None
        return e, (None if g is None else g.ravel()), None, blocks

    def add_to(
        self, rod: BandedMatrix | SparseMatrix, contact: HessianBlocks | DofBlocks
    ) -> BandedMatrix | SparseMatrix:
        """The rod Hessian plus the contact Hessian on the grown :class:`HessianPattern` (the
        rod Hessian itself when no contact entry falls on free coordinates)."""
        base = banded_to_csc(rod) if isinstance(rod, BandedMatrix) else rod.csc
        total = self.pattern.add(base, contact, self._coord_reduced)
        return rod if total is None else total

    @property
    def analyses(self) -> int:
        """Symbolic analyses done on the shared pattern (for benchmarks)."""
        return self.pattern.analyses

    # ------------------------------------------------------------------ steps
    def step_bound(
        self,
        pos: FloatArray,
        dpos: FloatArray,
        directors: tuple[FloatArray, FloatArray] | None = None,
    ) -> float:
        """Provably contact-free fraction of the straight step ``pos -> pos + dpos``;
        ``directors``: m1 at the start and the end of the step (a stacked contact: the layer
        points' straight path)."""
        if isinstance(self.potential, StackedContact):
            assert directors is not None
            return self.potential.step_bound((pos, directors[0]), (pos + dpos, directors[1]))
        return self.potential.step_bound(pos, dpos)

    def path_is_free(
        self,
        start: FloatArray,
        end: FloatArray,
        directors: tuple[FloatArray, FloatArray] | None = None,
    ) -> bool:
        """Whether the straight path between two configurations never touches
        (``directors`` as for :meth:`step_bound`)."""
        if isinstance(self.potential, StackedContact):
            assert directors is not None
            return self.potential.path_is_free((start, directors[0]), (end, directors[1]))
        return self.potential.path_is_free(start, end)


def banded_to_csc(H: BandedMatrix) -> sp.csc_matrix:
    """The full symmetric CSC matrix of upper banded storage."""
    n, u = H.n, H.u
    rows, cols, vals = [], [], []
    for k in range(u + 1):
        d = H.ab[u - k, k:]
        i = np.arange(n - k)
        rows += [i, i + k] if k else [i]
        cols += [i + k, i] if k else [i]
        vals += [d, d] if k else [d]
    return sp.csc_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    )


def tangent_rigid_modes(
    positions: FloatArray,
    tangents: FloatArray,
    normal: FloatArray,
    pos_dof: IntArray,
    theta_dof: IntArray,
    ndof: int,
) -> FloatArray:
    """Rigid motions tangent to a plane of ``normal``: two translations and the rotation
    about the normal through the centroid (with its twist part ``n·t``), ``(3, ndof)``."""
    n = np.asarray(normal, float) / np.linalg.norm(normal)
    a = _cross(n, np.array([1.0, 0.0, 0.0]))
    if np.linalg.norm(a) < 0.5:
        a = _cross(n, np.array([0.0, 1.0, 0.0]))
    a /= np.linalg.norm(a)
    b = _cross(n, a)
    modes = np.zeros((3, ndof))
    positions = np.ascontiguousarray(positions, dtype=float)
    _fill_tangent_modes(
        modes,
        np.ascontiguousarray(pos_dof, dtype=np.int64),
        np.ascontiguousarray(theta_dof, dtype=np.int64),
        a,
        b,
        n,
        positions,
        positions.mean(axis=0),
        tangents @ n,  # NumPy's (BLAS) products, as before
    )
    return modes


@njit(cache=True)
def _fill_tangent_modes(
    modes, pos_dof, theta_dof, a, b, n, positions, centroid, twist
):  # pragma: no cover - compiled
    """Rows of :func:`tangent_rigid_modes`: ``a``, ``b`` and ``n x (x - centroid)`` (the
    products and differences of :func:`_cross`) on the positions, ``twist`` on the angles."""
    for i in range(pos_dof.shape[0]):
        p = pos_dof[i]
        r0 = positions[i, 0] - centroid[0]
        r1 = positions[i, 1] - centroid[1]
        r2 = positions[i, 2] - centroid[2]
        for k in range(3):
            modes[0, p + k] = a[k]
            modes[1, p + k] = b[k]
        modes[2, p] = n[1] * r2 - n[2] * r1
        modes[2, p + 1] = n[2] * r0 - n[0] * r2
        modes[2, p + 2] = n[0] * r1 - n[1] * r0
    for j in range(theta_dof.shape[0]):
        modes[2, theta_dof[j]] = twist[j]


def _cross(u: FloatArray, v: FloatArray) -> FloatArray:
    """``np.cross(u, v)`` of a 3-vector ``u`` with ``(3,)`` or ``(N, 3)`` ``v``, by the same
    products and differences (bit-identical) without its generic axis handling, which costs
    ten times more at these sizes (the projection runs every Newton iteration)."""
    out = np.empty(np.shape(v))
    out[..., 0] = u[1] * v[..., 2] - u[2] * v[..., 1]
    out[..., 1] = u[2] * v[..., 0] - u[0] * v[..., 2]
    out[..., 2] = u[0] * v[..., 1] - u[1] * v[..., 0]
    return out


@njit(cache=True)
def _find(indices, lo, hi, row, hint):  # pragma: no cover - compiled
    """Position of ``row`` in the sorted ``indices[lo:hi]`` (-1: absent); ``hint + 1`` is
    tried first (the next coordinate of the same node)."""
    if lo <= hint + 1 < hi and indices[hint + 1] == row:
        return hint + 1
    end = hi
    while lo < hi:
        mid = (lo + hi) // 2
        if indices[mid] < row:
            lo = mid + 1
        else:
            hi = mid
    return lo if lo < end and indices[lo] == row else -1  # (not the next column's first row)


@njit(cache=True)
def _scatter_blocks(
    indptr, indices, coord_reduced, n_nodes, quads, pair, nodes, node, out, keys
):  # pragma: no cover - compiled
    """Add the non-zero free entries of the contact blocks into ``out`` (the data array of the
    CSC pattern ``indptr``, ``indices``); their number, or -1 when one is not in the pattern.

    With ``keys`` non-empty (room for every entry) the entries' keys ``column * n + row`` are
    written there instead (``n = len(indptr) - 1``) and nothing is looked up.
    """
    collect = keys.shape[0] > 0
    n = indptr.shape[0] - 1
    count = 0
    for p in range(quads.shape[0] + nodes.shape[0]):
        block = p < quads.shape[0]
        q = p - quads.shape[0]
        width = 4 if block else 1
        for a in range(width):
            na = quads[p, a] if block else nodes[q]
            if na >= n_nodes:
                continue  # an obstacle point
            for b in range(width):
                nb = quads[p, b] if block else nodes[q]
                if nb >= n_nodes:
                    continue
                for m in range(3):
                    c = coord_reduced[3 * nb + m]
                    if c < 0:
                        continue
                    pos = -2
                    for k in range(3):
                        r = coord_reduced[3 * na + k]
                        v = pair[p, 3 * a + k, 3 * b + m] if block else node[q, k, m]
                        if r < 0 or v == 0.0:
                            continue
                        if collect:
                            keys[count] = c * n + r
                        else:
                            pos = _find(indices, indptr[c], indptr[c + 1], r, pos)
                            if pos < 0:
                                return -1
                            out[pos] += v
                        count += 1
    return count


@njit(cache=True)
def _scatter_pairs(
    indptr, indices, coord_reduced, n_nodes, quads, pair, out, slot_of, slots, slot_quads, used
):  # pragma: no cover - compiled
    """The pair blocks of :func:`_scatter_blocks` (same entries, same order of additions),
    each pair's data positions looked up in ``slots[slot_of[pair]]`` and found (and stored
    in row ``used[0]``, which is then advanced, with the pair in ``slot_quads``) on its first
    appearance; ``slots`` and ``slot_quads`` must have a free row per pair. Returns the
    number of entries added, or -1 when one is not in the pattern."""
    count = 0
    for p in range(quads.shape[0]):
        key = (quads[p, 0], quads[p, 1], quads[p, 2], quads[p, 3])
        if key in slot_of:
            slot = slot_of[key]
        else:
            slot = used[0]
            used[0] += 1
            slot_of[key] = slot
            for a in range(4):
                slot_quads[slot, a] = quads[p, a]
            _find_slots(indptr, indices, coord_reduced, n_nodes, slot_quads, slot, slots, False)
        e = 0
        for a in range(4):
            for b in range(4):
                for m in range(3):
                    for k in range(3):
                        t = slots[slot, e]
                        e += 1
                        v = pair[p, 3 * a + k, 3 * b + m]
                        if t == -1 or v == 0.0:
                            continue
                        if t == -2:
                            return -1
                        out[t] += v
                        count += 1
    return count


@njit(cache=True)
def _find_slots(
    indptr, indices, coord_reduced, n_nodes, slot_quads, slot, slots, missing_only
):  # pragma: no cover - compiled
    """Data positions of the 144 entries of the pair ``slot_quads[slot]`` in the pattern, in
    the loop order of :func:`_scatter_blocks`, into ``slots[slot]`` (-1: not a free
    coordinate, -2: not in the pattern); with ``missing_only``, only the entries now -2."""
    e = 0
    for a in range(4):
        na = slot_quads[slot, a]
        for b in range(4):
            nb = slot_quads[slot, b]
            for m in range(3):
                c = coord_reduced[3 * nb + m] if nb < n_nodes else -1
                pos = -2
                for k in range(3):
                    if missing_only and slots[slot, e] != -2:
                        e += 1
                        pos = -2
                        continue
                    r = coord_reduced[3 * na + k] if na < n_nodes else -1
                    if c < 0 or r < 0:
                        slots[slot, e] = -1
                    else:
                        pos = _find(indices, indptr[c], indptr[c + 1], r, pos)
                        slots[slot, e] = pos if pos >= 0 else -2
                    e += 1


@njit(cache=True)
def _move_slots(
    slots, slot_quads, used, shift, coord_reduced, n_nodes, indptr, indices
):  # pragma: no cover - compiled
    """The remembered data positions after keys were inserted into the pattern: a position
    ``t`` moves to ``t + shift[t]``, and the entries that were not in the pattern are looked
    up again in the grown one (``indptr``, ``indices``)."""
    for slot in range(used):
        missing = False
        for e in range(144):
            t = slots[slot, e]
            if t >= 0:
                slots[slot, e] = t + shift[t]
            elif t == -2:
                missing = True
        if missing:
            _find_slots(indptr, indices, coord_reduced, n_nodes, slot_quads, slot, slots, True)


@njit(cache=True)
def _add_at(out, pos, values):  # pragma: no cover - compiled
    """``out[pos] += values`` for distinct positions ``pos``."""
    for k in range(pos.shape[0]):
        out[pos[k]] += values[k]


@njit(cache=True)
def _dof_keys(n, coord_reduced, dofs, blocks, keys):  # pragma: no cover - compiled
    """Keys ``column * n + row`` of the non-zero free entries of generalised blocks into
    ``keys``; their number."""
    count = 0
    width = dofs.shape[1]
    for p in range(dofs.shape[0]):
        for b in range(width):
            db = dofs[p, b]
            if db < 0:
                continue
            c = coord_reduced[db]
            if c < 0:
                continue
            for a in range(width):
                da = dofs[p, a]
                if da < 0:
                    continue
                r = coord_reduced[da]
                if r < 0 or blocks[p, a, b] == 0.0:
                    continue
                keys[count] = c * n + r
                count += 1
    return count


@njit(cache=True)
def _scatter_dof_blocks(
    indptr, indices, coord_reduced, dofs, blocks, bkeys, out, slot_of, slots, used
):  # pragma: no cover - compiled
    """Add the non-zero free entries of generalised blocks into ``out`` (the data array of the
    CSC pattern), each block's data positions remembered in ``slots[slot_of[key]]`` (-1: not
    a free coordinate, -2: not in the pattern); the number added, or -1 when an entry is not
    in the pattern."""
    width = dofs.shape[1]
    count = 0
    for p in range(dofs.shape[0]):
        key = bkeys[p]
        if key in slot_of:
            slot = slot_of[key]
        else:
            slot = used[0]
            used[0] += 1
            slot_of[key] = slot
            e = 0
            for b in range(width):
                db = dofs[p, b]
                c = coord_reduced[db] if db >= 0 else -1
                pos = -2
                for a in range(width):
                    da = dofs[p, a]
                    r = coord_reduced[da] if da >= 0 else -1
                    if c < 0 or r < 0:
                        slots[slot, e] = -1
                    else:
                        pos = _find(indices, indptr[c], indptr[c + 1], r, pos)
                        slots[slot, e] = pos if pos >= 0 else -2
                    e += 1
        e = 0
        for b in range(width):
            for a in range(width):
                t = slots[slot, e]
                e += 1
                v = blocks[p, a, b]
                if t == -1 or v == 0.0:
                    continue
                if t == -2:
                    # forget this block's positions: after the growth they are found again
                    del slot_of[key]
                    return -1
                out[t] += v
                count += 1
    return count
