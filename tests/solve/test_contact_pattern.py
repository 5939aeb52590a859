"""The contact Hessian added on the grown pattern: each pair block's data positions are found
once and remembered; the sums equal adding every block entry by entry (the same additions in
the same order, bit for bit), across pattern growth, fixed coordinates and obstacle points."""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from rotomorph.contact.potential import HessianBlocks
from rotomorph.solve.contact_term import HessianPattern, _scatter_blocks


def _blocks(rng: np.random.Generator, n_nodes: int, quads: np.ndarray) -> HessianBlocks:
    """Symmetric random pair blocks (a few entries exactly 0) and two floor blocks."""
    a = rng.standard_normal((len(quads), 12, 12))
    pair = a + a.transpose(0, 2, 1)
    pair[rng.random(pair.shape) < 0.05] = 0.0
    nodes = rng.choice(n_nodes, 2, replace=False)
    b = rng.standard_normal((2, 3, 3))
    return HessianBlocks(
        n_nodes=n_nodes,
        quads=np.ascontiguousarray(quads, dtype=np.int64),
        pair=pair,
        nodes=nodes.astype(np.int64),
        node=b + b.transpose(0, 2, 1),
    )


def _quads(rng: np.random.Generator, n_nodes: int, count: int) -> np.ndarray:
    """Segment pairs, node–segment pairs (a repeated node) and pairs with an obstacle's two
    points (indices n_nodes, n_nodes + 1)."""
    out = []
    for _ in range(count):
        i, j = rng.choice(n_nodes - 1, 2, replace=False)
        kind = rng.integers(3)
        if kind == 0:
            out.append([i, i + 1, j, j + 1])
        elif kind == 1:
            out.append([i, i, j, j + 1])
        else:
            out.append([i, i + 1, n_nodes, n_nodes + 1])
    return np.array(out)


def _reference(base: sp.csc_matrix, blocks: HessianBlocks, coord: np.ndarray, pattern):
    """``base + blocks`` on ``pattern`` (indices, indptr), every entry looked up anew."""
    indices, indptr = pattern
    out = np.zeros(len(indices))
    count = _scatter_blocks(
        indptr, indices, coord, blocks.n_nodes, blocks.quads, blocks.pair, blocks.nodes,
        blocks.node, out, np.zeros(0, dtype=np.int64),
    )  # fmt: skip
    assert count > 0
    full = sp.csc_matrix((out, indices, indptr), shape=base.shape) + base
    return full.toarray()


def test_remembered_positions_add_as_the_entry_by_entry_scatter():
    rng = np.random.default_rng(3)
    n_nodes = 30
    coord = np.arange(3 * n_nodes, dtype=np.int64)  # node coordinate -> free index
    coord[[4, 5, 40]] = -1  # some fixed coordinates
    free = coord >= 0
    coord[free] = np.arange(free.sum())
    n = int(free.sum())
    base = sp.csc_matrix(sp.diags(np.arange(1.0, n + 1)) + sp.eye(n, k=1) + sp.eye(n, k=-1))
    pattern = HessianPattern()
    pool = _quads(rng, n_nodes, 40)
    seen = 0
    for call in range(30):
        # mostly pairs seen before (their positions remembered), some new ones (the pattern
        # grows and every remembered position moves)
        quads = pool[rng.choice(10 + call, size=8, replace=False)]
        blocks = _blocks(rng, n_nodes, quads)
        total = pattern.add(base, blocks, coord)
        assert total is not None
        union = pattern._union
        expected = _reference(base, blocks, coord, union)
        assert np.array_equal(total.csc.toarray(), expected)
        seen = max(seen, int(pattern._used[0]))
    assert pattern.analyses > 5  # the pattern grew many times
    assert seen > 8  # and positions were remembered between growths


def test_an_entry_outside_the_pattern_grows_it_even_when_the_pair_is_remembered():
    """A pair first seen with a zero block entry (not added to the pattern) and later with
    that entry non-zero: the remembered position says 'not in the pattern', the pattern grows
    by it and the sum is right."""
    rng = np.random.default_rng(4)
    n_nodes = 12
    coord = np.arange(3 * n_nodes, dtype=np.int64)
    n = 3 * n_nodes
    base = sp.csc_matrix(sp.eye(n))
    quads = np.array([[0, 1, 6, 7]])
    blocks = _blocks(rng, n_nodes, quads)
    sparse = blocks.pair.copy()
    sparse[0, :6, 6:] = 0.0  # no coupling between the two segments yet
    sparse[0, 6:, :6] = 0.0
    pattern = HessianPattern()
    first = pattern.add(
        base, HessianBlocks(n_nodes, quads, sparse, blocks.nodes, blocks.node), coord
    )
    assert first is not None and first.csc[0, 18] == 0.0
    again = pattern.add(base, blocks, coord)
    assert again is not None
    assert np.array_equal(again.csc.toarray(), _reference(base, blocks, coord, pattern._union))
    assert again.csc[0, 18] == blocks.pair[0, 0, 6]


def test_a_grown_pattern_equals_one_built_afresh_from_its_keys():
    """Growing the union by inserting keys (and moving the stored positions) gives the arrays,
    base positions and symbolic analysis that a fresh build from all the keys gives; the base
    pattern changing midway (a coupling the contact blocks do not have) included."""
    from rotomorph.solve.sparse_cholesky import analyse

    rng = np.random.default_rng(5)
    n_nodes = 25
    coord = np.arange(3 * n_nodes, dtype=np.int64)
    n = 3 * n_nodes
    tri = sp.diags(np.arange(1.0, n + 1)) + sp.eye(n, k=1) + sp.eye(n, k=-1)
    wider = sp.csc_matrix(tri + 0.5 * (sp.eye(n, k=7) + sp.eye(n, k=-7)))
    pattern = HessianPattern()
    pool = _quads(rng, n_nodes, 30)
    keys = []
    for call in range(20):
        base = sp.csc_matrix(tri) if call < 10 else wider
        blocks = _blocks(rng, n_nodes, pool[rng.choice(10 + call, size=6, replace=False)])
        total = pattern.add(base, blocks, coord)
        assert total is not None
        found = np.zeros(144 * len(blocks.quads) + 9 * len(blocks.nodes), dtype=np.int64)
        count = _scatter_blocks(
            np.zeros(n + 1, dtype=np.int32), np.zeros(0, dtype=np.int32), coord, n_nodes,
            blocks.quads, blocks.pair, blocks.nodes, blocks.node, np.zeros(0), found,
        )  # fmt: skip
        coo = base.tocoo()
        keys += [found[:count], coo.col.astype(np.int64) * n + coo.row]
        union = np.unique(np.concatenate(keys))
        assert np.array_equal(pattern._keys, union)
        rows, indptr = pattern._union
        assert np.array_equal(rows, union % n)
        assert np.array_equal(indptr, np.searchsorted(union // n, np.arange(n + 1)))
        bkeys = np.repeat(np.arange(n), np.diff(base.indptr)) * n + base.indices
        assert np.array_equal(pattern._base_pos, np.searchsorted(union, bkeys))
        fresh = analyse(sp.csc_matrix((np.ones(len(rows)), rows, indptr), shape=(n, n)),
                        pattern._sym.perm)  # fmt: skip
        for name in ("bp", "bi", "src", "diag_src", "parent", "lp"):
            assert np.array_equal(getattr(pattern._sym, name), getattr(fresh, name)), name
        assert np.array_equal(total.csc.toarray(), _reference(base, blocks, coord, pattern._union))
    assert pattern.analyses > 5 and int(pattern._used[0]) > 10


def test_an_absent_entry_is_not_found_in_the_next_column():
    """Looking up an entry that is not in its column, whose row is the first row of the next
    column, says 'absent' (a position there would add the value to the wrong entry)."""
    from rotomorph.solve.contact_term import _find

    indices = np.array([0, 2, 1, 2], dtype=np.int32)  # column 0: rows 0, 2; column 1: 1, 2
    assert _find(indices, 0, 2, 1, -2) == -1
    assert _find(indices, 0, 2, 2, -2) == 1
    assert _find(indices, 2, 4, 1, -2) == 2
