"""The lift probe's search solves: the weightless buckling stops at the search tolerance without
a certificate, each candidate laid on the floor settles first with a softer barrier
(uncertified) and then with the ramp's barrier to the ramp's tolerance, certified; the states
the ramp reports are those of the probe that converged every search solve to the ramp's
tolerance with the ramp's barrier."""

from __future__ import annotations

import inspect
from dataclasses import replace

import numpy as np
import pytest

import rotomorph.lattice.heating as heating
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice.heating import RAMP_OPTIONS, heat_lattice, lattice_gravity
from rotomorph.lattice.paths import shape_distance

ACT = "swapped"  # the flat state is an equilibrium: the probe lifts the dome


@pytest.fixture(scope="module")
def dome():
    return sinusoidal_lattice(n=5, ghost_nodes=4, pattern="dome")


def _ramp(dome):
    return heat_lattice(dome, actuation=ACT, steps=8, floor=True, gravity=lattice_gravity(dome))


@pytest.fixture(scope="module")
def recorded(dome):
    calls = []
    real = heating.solve_static

    signature = inspect.signature(real)

    def spy(*args, **kwargs):
        res = real(*args, **kwargs)
        a = signature.bind(*args, **kwargs).arguments
        calls.append((a["loads"], a["options"], a["contact"], a["initial"], res))
        return res

    mp = pytest.MonkeyPatch()
    mp.setattr(heating, "solve_static", spy)
    mp.setattr(heating, "SETTLE_SOFTENING", 0.01)
    mp.setattr(heating, "SEARCH_RTOL", 1e-4)
    mp.setattr(heating, "SEARCH_CERTIFY", False)
    try:
        result = _ramp(dome)
    finally:
        mp.undo()
    return result, calls


def test_search_solves_are_searches_and_reported_states_are_certified(recorded):
    result, calls = recorded
    ramp_scale = max(c.stiffness_scale for _, _, c, _, _ in calls)
    weightless = [o for ld, o, _, _, _ in calls if ld.gravity is None]
    assert weightless, "the probe never buckled the weightless lattice"
    for o in weightless:
        assert o.rtol == max(RAMP_OPTIONS.rtol, 1e-4)
        assert o.check_stability is False
    soft = [
        k
        for k, (ld, _, c, _, _) in enumerate(calls)
        if ld.gravity is not None and c.stiffness_scale < ramp_scale
    ]
    assert soft, "no candidate was settled with the softer barrier"
    for k in soft:
        _, o, c, _, res = calls[k]
        assert c.stiffness_scale == pytest.approx(0.01 * ramp_scale)
        assert o.rtol == RAMP_OPTIONS.rtol and not o.check_stability
        # the next solve starts where it ended, with the ramp's barrier, certified
        _, o2, c2, start, _ = calls[k + 1]
        assert c2.stiffness_scale == ramp_scale and o2.check_stability
        assert np.array_equal(start.positions, res.state.positions)
    assert all(result.stable)
    assert result.floor_lift[-1] > 2.0 * result.lattice.radius  # the probe lifted it


def test_the_same_end_state_as_a_probe_that_converges_every_search(recorded, dome):
    result, _ = recorded
    plain = _ramp(dome)  # the defaults: every search to the ramp's tolerance, certified
    assert heating.SETTLE_SOFTENING is None and heating.SEARCH_CERTIFY
    assert all(plain.stable)
    np.testing.assert_allclose(result.energy, plain.energy, rtol=1e-9, atol=1e-12)
    # the same shape, to well below the path check's tolerance (in-plane rigid motions on
    # the frictionless floor are free, so the shapes are compared after alignment)
    for a, b in zip(result.positions, plain.positions, strict=True):
        assert shape_distance(a, b) <= 1e-5 * float(dome.spacing)
    assert np.array_equal(result.gaussian_sign, plain.gaussian_sign)


def _filament_above_floor(height: float):
    from rotomorph.contact import Contact, Floor
    from rotomorph.rod.model import Model
    from rotomorph.solve.loads import Gravity, Loads, Supports

    r = 0.3
    x = np.linspace(0.0, 10.0, 21)
    model = Model.chain(
        np.stack([x, 0 * x, np.full_like(x, height * r)], 1),
        bending_stiffness1=0.006,
        bending_stiffness2=0.006,
        twist_stiffness=0.004,
        axial_stiffness=0.3,
    )
    loads = Loads(gravity=Gravity(density=1.1, area=np.pi * r**2, fluid_density=0.97))
    contact = Contact(radius=r, obstacles=(Floor(height=0.0),))
    return model, Supports(), loads, contact


def test_a_softened_settling_out_of_iterations_hands_on_its_last_iterate(monkeypatch):
    monkeypatch.setattr(heating, "SETTLE_SOFTENING", 0.01)
    model, sup, loads, contact = _filament_above_floor(3.0)
    start = model.reference_state()
    opts = replace(RAMP_OPTIONS, max_iterations=2)
    state, spent = heating._settle_softened(model, sup, loads, start, opts, contact)
    assert spent == 2
    assert not np.array_equal(state.positions, start.positions)  # it moved: kept, not dropped
    # converged: the softened equilibrium, which the ramp's barrier then corrects
    state, spent = heating._settle_softened(model, sup, loads, start, RAMP_OPTIONS, contact)
    assert 0 < spent < RAMP_OPTIONS.max_iterations
    # resting on the floor under its weight, never through the barrier's wall (the compliant
    # zone reaches 1 % of the diameter past touching)
    assert 0.3 - 0.01 * 0.6 < np.min(state.positions[:, 2]) < 0.3 + 0.01 * 0.6


def test_a_softened_settling_that_cannot_start_hands_back_the_start(monkeypatch):
    monkeypatch.setattr(heating, "SETTLE_SOFTENING", 0.01)
    model, sup, loads, contact = _filament_above_floor(0.5)  # already through the floor
    start = model.reference_state()
    state, spent = heating._settle_softened(model, sup, loads, start, RAMP_OPTIONS, contact)
    assert state is start and spent == 0
