"""Admissibility of lattice states: the printed stack's layers never pass through each other."""

from __future__ import annotations

import numpy as np
import pytest

import rotomorph.lattice.heating as heating
from rotomorph.contact import Contact
from rotomorph.contact.stack import StackOverlaps
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.actuation import CurvatureScaling
from rotomorph.lattice.admissibility import Admissibility, admissibility, lattice_stack
from rotomorph.lattice.heating import RAMP_OPTIONS, heat_lattice, lattice_gravity
from rotomorph.lattice.model import lattice_model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.static import solve_static


def _up(lattice):  # type: ignore[no-untyped-def]
    return np.tile([0.0, 0.0, 1.0], (lattice.network.n_edges, 1))


def test_the_printed_lattice_and_its_rigid_motions_are_admissible() -> None:
    lat = sinusoidal_lattice(5, pattern="dome")
    lm = lattice_model(lat)
    assert lattice_stack(lat).offsets == pytest.approx((-0.6, 0.0, 0.6))
    printed = admissibility(lat, lm.model.reference_state())
    assert printed.admissible and printed.count == 0 and printed.deepest == 0.0
    assert "no two layers interpenetrate" in printed.text()
    c, s = np.cos(0.4), np.sin(0.4)
    rot = np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])
    moved = admissibility(lat, (lat.network.nodes @ rot.T + 3.0, _up(lat) @ rot.T))
    assert moved.admissible


def test_centre_line_contact_leaves_the_stack_interpenetrating_one_filament_not() -> None:
    """Contact on the centre line alone (one capsule of the filament radius) keeps the centre
    lines a diameter apart, not the stacks: a curling 3 x 3 lattice ends with its layers
    through each other, the same states read as one-layer lattices are admissible."""
    lat = sinusoidal_lattice(3, ghost_nodes=6, pattern="contracting")
    res = heat_lattice(lat, steps=4, contact=Contact(radius=lat.radius))
    assert res.stack_overlaps is not None and res.stack_overlaps[0] == 0
    assert res.stack_overlaps[-1] > 0 and res.admissible[-1] is False
    assert res.physical[-1] is False and res.stable[-1] is True
    bad = admissibility(lat, res.states[-1], contact=res.contact)
    assert bad.count == res.stack_overlaps[-1] and 0.0 < bad.deepest <= 0.6
    assert "layer pairs of the printed 3-layer stack interpenetrate" in bad.text()
    assert len(bad.overlaps.segment_pairs()) <= bad.count
    one = sinusoidal_lattice(3, ghost_nodes=6, pattern="contracting", layers=1)
    assert all(admissibility(one, s, contact=res.contact).admissible for s in res.states)


def test_shapes_are_checked() -> None:
    lat = sinusoidal_lattice(3)
    with pytest.raises(InvalidParameterError, match="state"):
        admissibility(lat, (np.zeros((3, 3)), np.zeros((3, 3))))


def test_every_ramp_step_is_checked_and_the_printed_one_passes() -> None:
    lat = sinusoidal_lattice(3, ghost_nodes=4, pattern="dome")
    res = heat_lattice(lat, actuation="swapped", steps=2)
    assert res.stack_overlaps is not None and len(res.stack_overlaps) == 3
    assert res.stack_overlaps[0] == 0 and res.admissible[0] is True
    assert res.physical == tuple(
        s is True and c == 0 for s, c in zip(res.stable, res.stack_overlaps, strict=True)
    )


def test_the_lift_probe_never_takes_an_inadmissible_lattice(monkeypatch) -> None:
    """The dome of the floor tests lifts off at ramp step k (tests/contact/
    test_floor_lift_off.py); the probe at step k, run again on the resting state, finds that
    lifted dome, and with its candidates declared inadmissible it must return none."""
    dome = sinusoidal_lattice(n=5, ghost_nodes=4, pattern="dome")
    kw = dict(floor=True, gravity=lattice_gravity(dome))
    best = heat_lattice(dome, actuation="swapped", steps=8, **kw)
    k = int(np.flatnonzero(best.floor_lift > 2.0 * dome.radius)[0])
    act = CurvatureScaling("swapped", end=float(best.parameter[k]))
    rest = heat_lattice(dome, actuation=act, steps=k, branch="continuous", **kw)
    model = act.natural(rest.model, act.end)
    loads = Loads(gravity=lattice_gravity(dome))
    assert rest.contact is not None and rest.contact.floor is not None
    resting = solve_static(
        model, Supports(), loads, initial=rest.states[-1], options=RAMP_OPTIONS,
        contact=rest.contact,
    )  # fmt: skip
    probe = (model, Supports(), loads, rest.contact, resting, RAMP_OPTIONS, rest.contact.floor)
    lifted, gap, _ = heating._lift_probe(*probe, dome)
    assert lifted is not None and gap is not None and gap < 0.0
    overlapping = Admissibility(
        StackOverlaps(np.array([[0, 9]]), np.array([[2, 0]]), np.array([0.1]), np.array([0.6])),
        3,
    )
    monkeypatch.setattr(heating, "admissibility", lambda *a, **kw: overlapping)
    lifted, _, _ = heating._lift_probe(*probe, dome)
    assert lifted is None
