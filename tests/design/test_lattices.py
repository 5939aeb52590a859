"""The paper's sinusoidal lattice: counts, ghost-node formula, patterns, print programs."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidDesignError


@pytest.fixture(scope="module")
def lattice():
    return sinusoidal_lattice(5, spacing=5.0, amplitude=1.25, ghost_nodes=10, pattern="dome")


def test_paper_counts(lattice):
    net = lattice.network
    assert (net.n_nodes, net.n_edges, len(lattice.edge_chains)) == (425, 440, 40)
    assert net.branch.sum() == 25 and net.branch[:25].all()
    assert lattice.n_junction_pairs == 94 == 4 * 1 + 12 * 3 + 9 * 6


def test_branch_nodes_row_major(lattice):
    pos = lattice.branch_positions
    for i, j in [(0, 0), (1, 3), (4, 2)]:
        k = lattice.branch_index(i, j)
        assert k == 5 * i + j
        np.testing.assert_allclose(pos[k], [5.0 * i, 5.0 * j, 0.0])


def test_ghost_nodes_follow_the_paper_formula_with_n_equal_z_cross_t(lattice):
    nodes = lattice.network.nodes
    s = np.arange(1, 11)
    for e, chain in enumerate(lattice.edge_chains):
        a, b = lattice.edge_nodes[e]
        assert chain[0] == a and chain[-1] == b and b > a
        t = (nodes[b] - nodes[a]) / 5.0
        n = np.cross([0, 0, 1.0], t)
        expect = (
            nodes[a] + np.outer(s * 5.0 / 11, t) + np.outer(1.25 * np.sin(2 * np.pi * s / 11), n)
        )
        np.testing.assert_allclose(nodes[chain[1:-1]], expect, atol=1e-12)
    # the network segments run along the chains, in edge order
    np.testing.assert_array_equal(lattice.network.edges[:11, 0], lattice.edge_chains[0][:-1])


def test_edge_order_x_then_y(lattice):
    assert lattice.edge_direction[:20] == ("x",) * 20
    assert lattice.edge_direction[20:] == ("y",) * 20
    assert tuple(lattice.edge_nodes[0]) == (0, 5) and tuple(lattice.edge_nodes[20]) == (0, 1)


@pytest.mark.parametrize(
    ("pattern", "centre", "n_expanding"),
    [
        ("expanding", "central_cells", 40),
        ("contracting", "central_cells", 0),
        ("dome", "central_cells", 12),
        ("saddle", "central_cells", 28),
        ("dome", "interior", 24),
        ("saddle", "interior", 16),
    ],
)
def test_patterns(pattern, centre, n_expanding):
    lat = sinusoidal_lattice(pattern=pattern, centre=centre, ghost_nodes=2)
    assert lat.edge_mode.count("expanding") == n_expanding
    if pattern == "dome" and centre == "central_cells":
        i, j = np.divmod(lat.edge_nodes, 5)
        inner = ((i > 0) & (i < 4) & (j > 0) & (j < 4)).all(axis=1)
        assert all((m == "expanding") == c for m, c in zip(lat.edge_mode, inner, strict=True))


def test_custom_patterns_and_errors():
    modes = ["contracting"] * 40
    modes[7] = "expanding"
    assert sinusoidal_lattice(pattern=modes, ghost_nodes=1).edge_mode[7] == "expanding"
    mapping = {(0, 5): "expanding"} | {e: "contracting" for e in range(1, 40)}
    assert sinusoidal_lattice(pattern=mapping, ghost_nodes=1).edge_mode[0] == "expanding"
    with pytest.raises(InvalidDesignError, match="misses edge 0"):
        sinusoidal_lattice(pattern={1: "expanding"})
    with pytest.raises(InvalidDesignError, match=r"pattern\[3\]"):
        sinusoidal_lattice(pattern=["expanding"] * 3 + ["curly"] + ["expanding"] * 36)
    with pytest.raises(InvalidDesignError, match="pattern"):
        sinusoidal_lattice(pattern="wavy")
    with pytest.raises(InvalidDesignError, match="centre"):
        sinusoidal_lattice(pattern="dome", centre="middle")
    with pytest.raises(InvalidDesignError, match="spacing"):
        sinusoidal_lattice(spacing=0.0)


def test_interface_angle_flips_along_each_edge(lattice):
    alpha = lattice.interface_angle.reshape(40, 11)
    side = lattice.segment_side.reshape(40, 11)
    # one sine period: one half with the active side on one side, a flip segment, the other half
    assert np.all(side[:, 5] == 0)
    assert np.all(side[:, :5] == side[:, [0]]) and np.all(side[:, 6:] == -side[:, [0]])
    np.testing.assert_allclose(np.abs(alpha[:, [0, 1, 9, 10]]), np.pi / 2)
    # first half of every edge turns right (z x T side first): expanding = active outer = left
    expanding = np.array([m == "expanding" for m in lattice.edge_mode])
    assert np.all(side[expanding, 0] == 1) and np.all(side[~expanding, 0] == -1)


def test_print_programs_cover_the_network_and_keep_the_active_side(lattice):
    progs = lattice.print_programs(subdivide=4)
    assert len(progs) == 2 * 5 * 3
    assert [p.layer for p in progs] == [k for k in range(3) for _ in range(10)]
    np.testing.assert_allclose(progs[12].points[:, 2], 0.6)
    nodes = lattice.network.nodes
    alpha = lattice.interface_angle
    per = 11
    for prog, line in zip(progs[:10], lattice.line_edges, strict=True):
        chain = [lattice.edge_chains[e][:-1] for e in line] + [lattice.edge_chains[line[-1]][-1:]]
        np.testing.assert_allclose(prog.points[::4], nodes[np.concatenate(chain)], atol=1e-12)
        # program α averaged over each network segment matches the design α away from flips
        pa = prog.interface_angle.reshape(-1, 4).mean(axis=1)
        design = np.concatenate([alpha[e * per : (e + 1) * per] for e in line])
        # (the flip segment, its neighbours and the segments at branch nodes are excluded)
        k = np.arange(len(design)) % per
        steady = (k != 0) & (k != per - 1) & (np.abs(k - 5) > 1)
        assert np.max(np.abs(pa[steady] - design[steady])) < 0.05
        assert np.max(np.abs(prog.rotation)) < 40.0


def test_layers_parameter():
    lat = sinusoidal_lattice(n=3, ghost_nodes=3, layers=1)
    assert len(lat.print_programs()) == 6
    assert lat.network.n_nodes == 9 + 12 * 3


def test_edge_speeds_set_the_speed_of_every_move_along_their_edge():
    speeds = np.linspace(0.5, 3.0, 12)
    lat = sinusoidal_lattice(n=3, ghost_nodes=4, edge_speeds=speeds)
    assert np.array_equal(lat.speeds, speeds)
    assert np.array_equal(sinusoidal_lattice(n=3, speed=2.0).speeds, np.full(12, 2.0))
    for line, (prog, _), vertex_edges in zip(
        lat.line_edges, lat.line_programs(), lat.line_speed_edges(), strict=True
    ):
        # a vertex carries the speed of the move leaving it: edge e's moves all at v_e
        assert np.array_equal(prog.speed[:-1], np.repeat(speeds[line], 5))
        assert np.array_equal(prog.speed, speeds[vertex_edges])
    # toolpath resolution: the same speeds, four vertices per segment
    assert np.array_equal(lat.print_programs(4)[0].speed[:-1], np.repeat(speeds[:2], 20))


@pytest.mark.parametrize(
    ("speeds", "field"),
    [([1.0] * 11, "edge_speeds"), ([1.0] * 11 + [-2.0], r"edge_speeds\[11\]"),
     ([1.0] * 11 + [np.nan], r"edge_speeds\[11\]"), (["a"] * 12, "edge_speeds")],
)  # fmt: skip
def test_bad_edge_speeds_name_the_field(speeds, field):
    with pytest.raises(InvalidDesignError, match=field):
        sinusoidal_lattice(n=3, ghost_nodes=4, edge_speeds=speeds)
