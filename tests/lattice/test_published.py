"""The authors' Fig. 4 set-up: geometry, numbering and edge classes as their files write them.

The referee is an independent transcription of their ``robotDescription.cpp`` loops (limb by
limb in their order, their sine along the right-hand normal, their index formulas), not this
package's generator; the actuation is checked vertex by vertex against their controller's rule.
"""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.lattice import CurvatureScaling, lattice_model
from rotomorph.lattice.published import (
    EXPAND_LIMBS,
    NODES_PER_LIMB,
    SHRINK_LIMBS,
    SPACING,
    STRETCHES,
    UNLISTED_LIMBS,
    limb_edge,
    published_actuation,
    published_lattice,
)


def _their_limbs(step: float = SPACING, amplitude: float = 0.25 * SPACING, n: int = 10):
    """Their 40 limbs in their order: (start node, end node, nodes (n, 3)), as written in
    robotDescription.cpp (node i*5 + j at (step j, step i))."""
    side = 5
    limbs = []
    for i in range(side):  # along x
        for j in range(side - 1):
            start, end = (
                np.array([step * j, step * i, 0.0]),
                np.array([step * (j + 1), step * i, 0]),
            )
            perp = np.array([0.0, -1.0, 0.0])
            t = np.arange(n) / (n - 1)
            pts = (
                start + np.outer(t, end - start) + np.outer(amplitude * np.sin(2 * np.pi * t), perp)
            )
            limbs.append((i * side + j, i * side + j + 1, pts))
    for i in range(side - 1):  # along y
        for j in range(side):
            start, end = (
                np.array([step * j, step * i, 0.0]),
                np.array([step * j, step * (i + 1), 0]),
            )
            perp = np.array([1.0, 0.0, 0.0])
            t = np.arange(n) / (n - 1)
            pts = (
                start + np.outer(t, end - start) + np.outer(amplitude * np.sin(2 * np.pi * t), perp)
            )
            limbs.append((i * side + j, (i + 1) * side + j, pts))
    return limbs


def test_the_lattice_is_theirs_node_for_node():
    lat = published_lattice()
    x = lat.network.nodes
    limbs = _their_limbs()
    assert len(limbs) == len(lat.edge_chains) == 40
    assert lat.ghost_nodes == NODES_PER_LIMB - 2
    for limb, (_, _, pts) in enumerate(limbs):
        chain = lat.edge_chains[limb_edge(limb)]
        np.testing.assert_allclose(x[chain], pts, rtol=0, atol=1e-9 * SPACING)
    # every node once: 25 branch nodes and 8 ghosts per limb (their 345 floor-contact nodes)
    assert lat.network.n_nodes == 345
    assert sorted(limb_edge(k) for k in range(40)) == list(range(40))


def test_their_classes_are_the_central_cells_and_two_limbs_are_in_neither():
    expand, shrink, unlisted = set(EXPAND_LIMBS), set(SHRINK_LIMBS), set(UNLISTED_LIMBS)
    assert (len(expand), len(shrink)) == (12, 26)
    assert expand.isdisjoint(shrink) and unlisted == set(range(40)) - expand - shrink
    limbs = _their_limbs()

    def grid(node):
        return divmod(node, 5)  # (y, x) in their numbering

    interior = [all(0 < c < 4 for c in grid(a) + grid(b)) for a, b, _ in limbs]
    assert {k for k in range(40) if interior[k]} == expand  # the edges between interior nodes
    # limbs 29 and 30: the boundary limbs (4, 1) -> (4, 2) and (0, 2) -> (0, 3) (x, y)
    assert [(grid(limbs[k][0])[::-1], grid(limbs[k][1])[::-1]) for k in (29, 30)] == [
        ((4, 1), (4, 2)),
        ((0, 2), (0, 3)),
    ]
    lat = published_lattice()
    assert [lat.edge_mode[limb_edge(k)] for k in EXPAND_LIMBS] == ["expanding"] * 12


@pytest.mark.parametrize("stretch", [-0.17, 0.5])
def test_their_controller_rule_vertex_by_vertex(stretch):
    """κ̄ × (1 - stretch) on every interior vertex of an expand limb, × (1 + stretch) on a
    shrink limb, unchanged on limbs 29 and 30 and on every joint pair."""
    lat = published_lattice()
    lm = lattice_model(lat, stiffness="paper")
    model = published_actuation(0.0, stretch).natural(lm, stretch)
    k1, k2, _ = lm.printed
    st = lm.model.stencils
    edge = st.edge_e // (lat.ghost_nodes + 1)
    factor = np.ones(st.count)
    rod = ~np.asarray(st.junction, dtype=bool)
    for limbs, c in ((EXPAND_LIMBS, 1.0 - stretch), (SHRINK_LIMBS, 1.0 + stretch)):
        factor[rod & np.isin(edge, [limb_edge(k) for k in limbs])] = c
    n1, n2 = model.natural_curvature1, model.natural_curvature2
    np.testing.assert_allclose(n1, factor * k1, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(n2, factor * k2, rtol=1e-12, atol=1e-15)
    # the printed curvature is not zero on the unlisted limbs: leaving them out is a choice
    fixed = rod & np.isin(edge, [limb_edge(k) for k in UNLISTED_LIMBS])
    assert fixed.sum() == 2 * lat.ghost_nodes and np.abs(k2[fixed]).max() > 1e-4 / SPACING


def test_fixed_edges_are_checked():
    for bad in ((-1,), (True,), (1.5,)):
        with pytest.raises(InvalidParameterError, match=r"fixed_edges\[0\]"):
            CurvatureScaling("swapped", fixed_edges=bad)  # type: ignore[arg-type]
    lm = lattice_model(published_lattice(), stiffness="paper")
    with pytest.raises(InvalidParameterError, match=r"fixed_edges: must be lattice edges"):
        CurvatureScaling("swapped", fixed_edges=(40,)).natural(lm, 0.1)
    for bad in (-1, 40, 2.5, True):
        with pytest.raises(InvalidParameterError, match="limb"):
            limb_edge(bad)  # type: ignore[arg-type]


def test_the_stretch_grid():
    assert len(STRETCHES) == 151 and STRETCHES[0] == -0.75 and STRETCHES[-1] == 0.75
    np.testing.assert_allclose(np.diff(STRETCHES), 0.01, atol=1e-12)
    # their run.py: np.arange(-0.75, +0.75, +0.01) leaves +0.75 out
    theirs = np.arange(-0.75, +0.75, +0.01)
    assert len(theirs) == 150 and theirs[58] == pytest.approx(-0.17, abs=1e-12)
