"""The printed stack as contact geometry: layer capsules, their exclusion, their overlaps."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact.exclusion import excluded_pairs
from rotomorph.contact.stack import (
    Stack,
    layer_edges,
    layer_points,
    stack_exclusion,
    stack_overlaps,
)
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError

R = 0.3


def test_layered_offsets_are_centred_and_validated() -> None:
    assert Stack.layered(3, 0.6).offsets == pytest.approx((-0.6, 0.0, 0.6))
    assert Stack.layered(2, 0.5).offsets == pytest.approx((-0.25, 0.25))
    assert Stack.layered(1, 0.6).is_single
    assert Stack.layered(3, 0.6).extent == pytest.approx(0.6)
    with pytest.raises(InvalidParameterError, match="layers"):
        Stack.layered(0, 0.6)
    with pytest.raises(InvalidParameterError, match="layer_height"):
        Stack.layered(3, -1.0)
    with pytest.raises(InvalidParameterError, match="increase"):
        Stack((0.5, 0.0))


def test_layer_points_lie_along_the_director(rng) -> None:
    x = rng.standard_normal((5, 3))
    edges = np.array([[0, 1], [1, 2], [3, 4]])
    m1 = rng.standard_normal((3, 3))
    m1 /= np.linalg.norm(m1, axis=1)[:, None]
    offsets = (-0.6, 0.0, 0.6)
    pts = layer_points(x, edges, m1, offsets)
    ve = layer_edges(3, 3)
    for k, o in enumerate(offsets):
        for e in range(3):
            v = k * 3 + e
            assert np.allclose(pts[ve[v, 0]], x[edges[e, 0]] + o * m1[e])
            assert np.allclose(pts[ve[v, 1]], x[edges[e, 1]] + o * m1[e])


def test_one_layer_on_the_centre_line_excludes_what_contact_excludes() -> None:
    lat = sinusoidal_lattice(3)
    net = lat.network
    r = np.full(net.n_edges, R)
    up = np.tile([0.0, 0.0, 1.0], (net.n_edges, 1))
    mine = stack_exclusion(net.nodes, net.edges, up, r, Stack(), 0.018)
    theirs = excluded_pairs(net.nodes, net.edges, r, 0.018)
    assert np.array_equal(mine, theirs)


def _crossing(gap: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A rod along x at z = 0 and one along y at z = ``gap``, 20 segments each."""
    s = np.linspace(-5.0, 5.0, 21)
    a = np.column_stack([s, np.zeros_like(s), np.zeros_like(s)])
    b = np.column_stack([np.zeros_like(s), s, np.full_like(s, gap)])
    nodes = np.vstack([a, b])
    ea = np.column_stack([np.arange(20), np.arange(1, 21)])
    edges = np.vstack([ea, ea + 21])
    up = np.tile([0.0, 0.0, 1.0], (len(edges), 1))
    return nodes, edges, up


def test_stacked_rods_crossing_close_overlap_in_their_layers_only() -> None:
    # centre lines 1.0 mm apart (clear for one filament, 2r = 0.6) but three layers each, 0.6
    # apart: layers at z = {-0.6, 0, 0.6} and {0.4, 1.0, 1.6}; the pairs closer than 0.6 are
    # (0, 0.4), (0.6, 0.4), (0.6, 1.0)
    printed, edges, up = _crossing(3.0)  # printed far apart: nothing is fused
    stack = Stack.layered(3, 0.6)
    r = np.full(len(edges), R)
    excl = stack_exclusion(printed, edges, up, r, stack, 0.018)
    nodes, _, _ = _crossing(1.0)
    found = stack_overlaps(nodes, edges, up, r, stack, excl)
    layers = {tuple(p) for p in found.layers}
    assert layers == {(1, 0), (2, 0), (2, 1)}
    assert found.deepest == pytest.approx(0.6 - 0.2)
    assert set(np.unique(found.segments[:, 0])) <= set(range(20))
    assert set(np.unique(found.segments[:, 1])) <= set(range(20, 40))
    # the same rods as one filament each do not touch
    single = stack_overlaps(nodes, edges, up, r, Stack(), stack_exclusion(
        printed, edges, up, r, Stack(), 0.018))  # fmt: skip
    assert single.count == 0
    # turned on their sides (director along the other rod's axis) the layers clear each other
    side = np.vstack([np.tile([0.0, 1.0, 0.0], (20, 1)), np.tile([1.0, 0.0, 0.0], (20, 1))])
    assert stack_overlaps(nodes, edges, side, r, stack, excl).count == 0


def test_layers_of_one_stack_and_its_neighbours_never_count() -> None:
    # a straight stacked rod: its layers touch each other (0.6 apart = 2r) by construction
    nodes, edges, up = _crossing(10.0)
    stack = Stack.layered(3, 0.6)
    r = np.full(len(edges), R)
    excl = stack_exclusion(nodes, edges, up, r, stack, 0.018)
    assert stack_overlaps(nodes, edges, up, r, stack, excl).count == 0
    # a layer bent back over its own stack beyond the reach does count: fold rod A in two
    folded = nodes.copy()
    folded[11:21, 0] = folded[9::-1, 0][:10]
    folded[11:21, 2] = 1.0
    found = stack_overlaps(folded, edges, up, r, stack, excl)
    assert found.count > 0


@pytest.mark.parametrize(("depth", "counted"), [(0.5, 0), (0.99, 0), (1.01, 1), (2.0, 1)])
def test_an_overlap_counts_once_deeper_than_the_contact_offset(depth, counted) -> None:
    """Two crossing three-layer segments whose facing layers overlap by ``depth`` x the
    tolerance (the contact's offset, 6 um at the default): a pressed contact inside it is
    contact, a deeper overlap interpenetration; with no tolerance every overlap counts."""
    offset = 0.01 * 2 * R  # Contact.offset's default: the activation distance
    stack = Stack.layered(3, 0.6)
    gap = 2 * R + 2 * 0.6 - depth * offset  # centre lines; the facing layers overlap by depth
    x = np.array([[-1.0, 0, 0], [1.0, 0, 0], [0, -1.0, gap], [0, 1.0, gap]])
    edges = np.array([[0, 1], [2, 3]])
    up = np.tile([0.0, 0.0, 1.0], (2, 1))
    r = np.full(2, R)
    printed = x + np.array([0.0, 0.0, 5.0]) * (np.arange(4) >= 2)[:, None]  # printed apart
    excl = stack_exclusion(printed, edges, up, r, stack, offset)  # a segment's own layers
    found = stack_overlaps(x, edges, up, r, stack, excl, tolerance=offset)
    assert found.count == counted
    strict = stack_overlaps(x, edges, up, r, stack, excl)
    assert strict.count == 1
    assert strict.deepest == pytest.approx(depth * offset, rel=1e-9)
    # one layer each, nothing excluded: their centre lines are far apart
    assert stack_overlaps(x, edges, up, r, Stack(), np.zeros(0, dtype=np.int64)).count == 0
