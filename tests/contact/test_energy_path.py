"""The contact energy of a line-search trial (no gradient, no Hessian) is the full evaluation's,
to the bit; the compiled node motions (candidate reuse, step sizes) are NumPy's."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact import Contact, ContactPotential, Floor, Sphere
from rotomorph.contact.distance import box_excess, box_growth, node_motions
from rotomorph.contact.potential import _largest_norm
from rotomorph.design.network import Network


def test_node_motions_are_numpys_sums(rng):
    x = rng.normal(size=(50, 3)) * 10.0 ** rng.uniform(-3, 3, (50, 3))
    ref = x + rng.normal(size=x.shape) * 10.0 ** rng.uniform(-9, 0, x.shape)
    out = np.full(53, -1.0)  # three obstacle points after the nodes
    worst = node_motions(x, ref, out)
    expected = np.sqrt(((x - ref) ** 2).sum(axis=1))
    np.testing.assert_array_equal(out[:50], expected)
    np.testing.assert_array_equal(out[50:], 0.0)
    assert worst == expected.max()
    squares = (x**2).sum(axis=1)
    assert _largest_norm(x) == np.sqrt(squares).max() == np.sqrt(squares.max())
    assert _largest_norm(np.zeros((0, 3))) == 0.0
    x[7, 1] = np.nan  # a NaN motion is the largest, as NumPy's max has it
    assert np.isnan(node_motions(x, ref, out))


def test_step_boxes_are_numpys(rng):
    """How far a step's boxes reach beyond the reused candidates' positions, and how far a
    trial lies outside the boxes its step bound swept: NumPy's element-wise values."""
    for n in (1, 7, 40):
        x = rng.normal(size=(n, 3))
        x0 = x + 1e-3 * rng.normal(size=(n, 3))
        x1 = x0 + 1e-2 * rng.normal(size=(n, 3))
        y = x0 + rng.uniform(-0.1, 1.1, (n, 1)) * (x1 - x0) + 1e-4 * rng.normal(size=(n, 3))
        grown = np.maximum(np.abs(x0 - x), np.abs(x1 - x)).max(axis=0)
        np.testing.assert_array_equal(box_growth(x0, x1, x), grown)
        outside = np.maximum(np.minimum(x0, x1) - y, y - np.maximum(x0, x1)).max()
        assert box_excess(x0, x1, y) == outside
    x0[3, 1] = np.nan  # NaN as NumPy's maxima have it: no reuse on it
    assert np.isnan(box_growth(x0, x1, x)[1]) and not np.isnan(box_growth(x0, x1, x)[0])
    assert np.isnan(box_excess(x0, x1, y))


@pytest.mark.parametrize("friction", [0.0, 0.4], ids=["frictionless", "friction"])
def test_energy_only_evaluation_is_the_full_one_to_the_bit(rng, friction):
    """A hairpin filament (two rows side by side) on a floor and under a sphere: self pairs,
    floor nodes, an obstacle point pair and (with friction) the lagged friction all active."""
    half = np.linspace(0.0, 6.0, 12)
    pts = np.r_[  # pressed 1-4 % of a radius into the floor, each other and the sphere
        np.c_[half, 0 * half, 0.23 + 0.001 * half],
        np.c_[half[::-1], 0.49 + 0 * half, 0.24 + 0 * half],
    ]
    net = Network(pts, np.c_[np.arange(23), np.arange(1, 24)])
    contact = Contact(
        radius=0.25,
        obstacles=(Floor(height=0.0), Sphere(centre=(3.0, 0.245, 1.946), radius=1.5)),
        activation_distance=0.05,
        stiffness=1.0,
        friction=friction,
    )
    pot = ContactPotential(contact, net)
    pot.set_lag(pts)
    active = 0
    for scale in (0.0, 1e-4, 3e-3):  # the first finds the candidates, the others reuse them
        x = pts + scale * rng.normal(size=pts.shape)
        energies = [pot.evaluate_blocks(x, g, h)[0] for g, h in ((False, 0), (True, 0), (True, 1))]
        assert all(e == energies[0] for e in energies), energies
        active = max(active, pot.active_contacts(x))
    assert np.isfinite(energies[0]) and energies[0] > 0.0
    assert active >= 10  # self pairs, sphere pairs and floor nodes (26 at the start)
