"""The unit-level Hessian pattern equals the one found by sorting every coupling."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.design.network import Network
from rotomorph.rod.stencils import build_stencils, dof_layout
from rotomorph.solve.pattern import hessian_pattern


def _by_sorting(
    stencil_dofs: np.ndarray, edge_dofs: np.ndarray, reduced: np.ndarray
) -> tuple[np.ndarray, np.ndarray, tuple[np.ndarray, np.ndarray]]:
    """Reference: list all 121 S + 36 E couplings, sort them, number the distinct ones."""
    nfree = int(np.sum(reduced >= 0))
    rs, re_ = reduced[stencil_dofs], reduced[edge_dofs]
    rows = np.concatenate([np.repeat(rs, 11, axis=1).ravel(), np.repeat(re_, 6, axis=1).ravel()])
    cols = np.concatenate([np.tile(rs, (1, 11)).ravel(), np.tile(re_, (1, 6)).ravel()])
    ok = (rows >= 0) & (cols >= 0)
    uniq, inv = np.unique(cols[ok] * nfree + rows[ok], return_inverse=True)
    slots = -np.ones(len(rows), dtype=np.int64)
    slots[ok] = inv
    ns = len(rs) * 121
    counts = np.bincount(uniq // nfree, minlength=nfree)
    indptr = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
    return (
        slots[:ns].reshape(-1, 11, 11),
        slots[ns:].reshape(-1, 6, 6),
        ((uniq % nfree).astype(np.int32), indptr),
    )


def _networks() -> list[Network]:
    rng = np.random.default_rng(0)
    star = Network(
        rng.normal(size=(7, 3)),
        np.array([[0, 1], [2, 0], [0, 3], [4, 0], [3, 5], [5, 6]]),
        np.array([True, False, False, False, False, False, False]),
    )
    return [
        sinusoidal_lattice(4).network,
        sinusoidal_lattice(3, ghost_nodes=1).network,
        Network.chain(rng.normal(size=(9, 3))),
        star,
    ]


@pytest.mark.parametrize("net", _networks())
@pytest.mark.parametrize("fixing", ["none", "first", "random", "thetas"])
def test_pattern_equals_sorting_every_coupling(net: Network, fixing: str) -> None:
    st, lay = build_stencils(net), dof_layout(net)
    fixed = np.zeros(lay.count, dtype=bool)
    if fixing == "first":
        fixed[:7] = True  # a whole node and part of the next unit
    elif fixing == "random":
        fixed[np.random.default_rng(1).random(lay.count) < 0.2] = True
    elif fixing == "thetas":
        fixed[lay.theta[:3]] = True
        fixed[lay.pos[-1] : lay.pos[-1] + 2] = True  # two of a node's three coordinates
    reduced = -np.ones(lay.count, dtype=np.int64)
    reduced[~fixed] = np.arange(int(np.sum(~fixed)))
    sd, ed = lay.stencil_dofs(st), lay.edge_dofs(net.edges)
    got, want = hessian_pattern(sd, ed, reduced), _by_sorting(sd, ed, reduced)
    for a, b in ((got[0], want[0]), (got[1], want[1]), (got[2][0], want[2][0])):
        assert a.dtype == b.dtype and np.array_equal(a, b)
    assert np.array_equal(got[2][1], want[2][1])
