"""Property: no accepted Newton iterate ever brings allowed pairs to where the barrier is infinite
(``r_a + r_b`` less the contact offset)."""

from __future__ import annotations

from unittest import mock

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from rotomorph.contact import Contact, ContactPotential, Floor
from rotomorph.contact.distance import pair_distances
from rotomorph.design.network import Network
from rotomorph.errors import ConvergenceError
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.static import solve_static


def _network(seed: int, chains: int, nodes: int, radius: float):
    """Chains stacked in z, each clamped at its start, crossing each other in plan view."""
    rng = np.random.default_rng(seed)
    pts, edges = [], []
    for k in range(chains):
        ang = rng.uniform(0, np.pi)
        s = np.linspace(-4, 4, nodes)
        bend = rng.uniform(-0.05, 0.05) * s**2
        p = np.stack(
            [s * np.cos(ang) - bend * np.sin(ang), s * np.sin(ang) + bend * np.cos(ang)], 1
        )
        z = np.full((nodes, 1), 1.5 * radius + k * (2 * radius + rng.uniform(0.05, 0.5)))
        start = k * nodes
        pts.append(np.hstack([p, z]))
        edges.append(start + np.stack([np.arange(nodes - 1), np.arange(1, nodes)], 1))
    return Network(np.vstack(pts), np.vstack(edges)), rng


@settings(max_examples=10, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    seed=st.integers(0, 10_000),
    chains=st.integers(2, 3),
    push=st.floats(0.5, 20.0),
    curl=st.floats(0.0, 0.6),
    floor=st.booleans(),
)
def test_accepted_iterates_never_interpenetrate(seed, chains, push, curl, floor):
    radius, nodes = 0.4, 11
    net, rng = _network(seed, chains, nodes, radius)
    ne = net.n_edges
    EI = np.pi * radius**4 / 4
    n_stencils = Model(net, EI, EI, EI / 1.5, 10.0).stencils.count
    model = Model(
        net,
        EI,
        EI,
        EI / 1.5,
        np.pi * radius**2,
        natural_curvature1=curl * rng.standard_normal(n_stencils),
        natural_curvature2=curl * rng.standard_normal(n_stencils),
    )
    mid = [k * nodes + nodes // 2 for k in range(chains)]
    ends = [k * nodes + nodes - 1 for k in range(chains)]
    force = push * EI / 16.0
    loads = Loads(
        forces=tuple((i, tuple(force * rng.uniform(-1, 1, 3) - [0, 0, force])) for i in mid + ends)
    )
    supports = Supports(clamped_edges=tuple(k * (nodes - 1) for k in range(chains)))
    contact = Contact(radius=radius, obstacles=(Floor(),) if floor else ())
    seen: list[np.ndarray] = []
    accept = RodObjective.accept

    def recording_accept(self, q):
        accept(self, q)
        seen.append(self.base.positions.copy())

    with mock.patch.object(RodObjective, "accept", recording_accept):
        try:
            solve_static(
                model, supports, loads, contact=contact, options=NewtonOptions(max_iterations=40)
            )
        except ConvergenceError:
            pass  # only the iterates matter here
    assert seen
    pot = ContactPotential(contact, net)
    i, j = np.triu_indices(ne, 1)
    keys = i * ne + j
    allowed = ~np.isin(keys, pot.excluded)
    quads = np.ascontiguousarray(np.hstack([net.edges[i[allowed]], net.edges[j[allowed]]]))
    # the barrier is infinite 1 % (its offset) inside r_a + r_b: no iterate ever reaches that,
    # however hard the loads press (up to 20 x the bending force scale here); a pressed
    # equilibrium settles a fraction of it inside
    wall = 2 * radius - pot.offset
    assert pot.offset == pytest.approx(0.01 * 2 * radius)
    for x in seen:
        d = pair_distances(np.ascontiguousarray(x), quads)
        assert d.min() > wall
        if floor:
            assert x[:, 2].min() > radius - pot.offset
