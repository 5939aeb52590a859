"""Heating ramps of small lattices with contact: no overlap, the floor carries the weight."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice import heat_lattice
from rotomorph.lattice.heating import lattice_gravity


def test_contracting_lattice_on_the_floor_jams_instead_of_overlapping():
    """One printed layer (its contact shape is one capsule per segment): kept on the floor it
    jams flat, and the lowest-energy branch crumples off the floor; a 3-layer stack is
    tested below."""
    lat = sinusoidal_lattice(n=3, pattern="contracting", layers=1)
    # the 'swapped' reading keeps this small case fast (10-25 Newton iterations per step)
    free = heat_lattice(lat, steps=4, actuation="swapped")
    kw = dict(steps=4, actuation="swapped", floor=True, gravity=lattice_gravity(lat))
    res = heat_lattice(lat, branch="continuous", **kw)  # kept on the floor: it jams flat
    assert free.min_clearance.min() < 0.9  # without contact, filaments overlap
    # allowed pairs, in units of r_a + r_b: pressed contacts settle within 0.5 % of touching
    # (the barrier acts from touching and is infinite 1 % inside)
    assert 0.995 < res.min_clearance.min() < 1.0
    assert res.contacts_active[-1] > 0
    assert res.final_area_ratio > free.final_area_ratio + 0.1
    assert res.floor_lift is not None and res.floor_lift[-1] < 2 * lat.radius  # stays flat
    assert res.first_lift_off() is None
    # the lowest-energy branch crumples off the floor instead, lower in energy, never overlapping
    best = heat_lattice(lat, **kw)
    assert best.min_clearance.min() > 0.995
    k = int(np.flatnonzero(best.floor_lift > 2 * lat.radius)[0])
    assert best.lift_energy_gap[k] < 0.0 and best.energy[-1] < res.energy[-1]


def test_a_stacked_contracting_lattice_jams_flat_with_its_layers_apart():
    """The same lattice printed in three layers: its stacks touch layer by layer, no lifted
    state the probe finds is admissible and lower, and no two layers ever interpenetrate."""
    lat = sinusoidal_lattice(n=3, pattern="contracting")
    kw = dict(steps=4, actuation="swapped", floor=True, gravity=lattice_gravity(lat))
    res = heat_lattice(lat, **kw)
    assert res.contact is not None and res.contact.stack.count == 3
    assert res.stack_overlaps is not None and not res.stack_overlaps.any()
    assert all(res.physical)
    # the barrier is infinite 1 % of the diameter inside touching (Contact.offset's default,
    # the activation distance) and pressed contacts settle within a small part of that
    assert res.min_clearance.min() >= 0.995 and res.contacts_active[-1] > 0
    # the floor lies under the bottom layer of the (perturbed) start: the stack rests on it
    assert res.contact.floor is not None
    start = res.states[0].positions[:, 2].min() - 0.6 - 1.005 * lat.radius
    assert -0.01 < res.contact.floor.height - start < 0.0


def test_gravity_on_a_free_lattice_needs_a_floor():
    lat = sinusoidal_lattice(n=2, ghost_nodes=2)
    with pytest.raises(InvalidParameterError, match="floor"):
        heat_lattice(lat, steps=1, gravity=lattice_gravity(lat))
    with pytest.raises(InvalidParameterError, match="friction"):
        heat_lattice(lat, steps=1, friction=0.3)


def test_friction_changes_the_contracting_jam_and_none_leaves_it_as_it_was(monkeypatch):
    """Coulomb friction (μ = 0.5) between the jamming filaments and with the floor, re-lagged
    within each step until the lagged normal forces converge: it changes the jammed area by
    1.3e-3 (the ramp's residual resolves about 1e-7), 1.7 x what friction lagged once per step
    at its start changes it (the jam forms within a step, its contacts carried no friction
    until the next one); without friction nothing is re-lagged and the ramp is the
    frictionless one, and never interpenetrates."""
    import rotomorph.lattice.heating as heating

    lat = sinusoidal_lattice(n=3, pattern="contracting")
    kw = dict(
        steps=4, actuation="swapped", floor=True, gravity=lattice_gravity(lat), branch="continuous"
    )
    slick = heat_lattice(lat, **kw)
    rough = heat_lattice(lat, friction=0.5, **kw)
    assert rough.contact is not None and rough.contact.friction == 0.5
    assert rough.total_iterations > 2 * slick.total_iterations  # the re-lagged solves
    change = float(rough.final_area_ratio - slick.final_area_ratio)
    assert abs(change) > 1e-3
    assert rough.min_clearance.min() > 0.995 and all(rough.stable[1:])
    monkeypatch.setattr(heating, "FRICTION_LAG_TOL", np.inf)  # lagged once per step
    once = heat_lattice(lat, friction=0.5, **kw)
    assert abs(change) > 1.5 * abs(float(once.final_area_ratio - slick.final_area_ratio)) > 0
    # friction 0: the ramp never re-lags (a fresh lattice: the contact Hessian's pattern grows
    # once per network, and the friction ramps above grew this one's)
    monkeypatch.setattr(heating, "relag_friction", None)
    again = heat_lattice(sinusoidal_lattice(n=3, pattern="contracting"), friction=0.0, **kw)
    np.testing.assert_array_equal(again.positions, slick.positions)
