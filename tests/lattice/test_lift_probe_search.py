"""The lift probe's search solves: the weightless buckling stops at the search tolerance without
a certificate, each candidate laid on the floor settles first with a softer barrier
(uncertified) and then with the ramp's barrier to the ramp's tolerance, certified; the states
the ramp reports are those of the probe that converged every search solve to the ramp's
tolerance with the ramp's barrier."""

from __future__ import annotations

import inspect

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
        assert o.rtol == max(RAMP_OPTIONS.rtol, heating.SEARCH_RTOL)
        assert o.check_stability is heating.SEARCH_CERTIFY is False
    soft = [
        k
        for k, (ld, _, c, _, _) in enumerate(calls)
        if ld.gravity is not None and c.stiffness_scale < ramp_scale
    ]
    assert soft, "no candidate was settled with the softer barrier"
    for k in soft:
        _, o, c, _, res = calls[k]
        assert c.stiffness_scale == pytest.approx(heating.SETTLE_SOFTENING * ramp_scale)
        assert o.rtol == RAMP_OPTIONS.rtol and not o.check_stability
        # the next solve starts where it ended, with the ramp's barrier, certified
        _, o2, c2, start, _ = calls[k + 1]
        assert c2.stiffness_scale == ramp_scale and o2.check_stability
        assert np.array_equal(start.positions, res.state.positions)
    assert all(result.stable)
    assert result.floor_lift[-1] > 2.0 * result.lattice.radius  # the probe lifted it


def test_the_same_end_state_as_a_probe_that_converges_every_search(recorded, dome):
    result, _ = recorded
    mp = pytest.MonkeyPatch()
    mp.setattr(heating, "SEARCH_RTOL", RAMP_OPTIONS.rtol)
    mp.setattr(heating, "SEARCH_CERTIFY", True)
    mp.setattr(heating, "SETTLE_SOFTENING", None)
    try:
        plain = _ramp(dome)
    finally:
        mp.undo()
    assert all(plain.stable)
    np.testing.assert_allclose(result.energy, plain.energy, rtol=1e-9, atol=1e-12)
    # the same shape, to well below the path check's tolerance (in-plane rigid motions on
    # the frictionless floor are free, so the shapes are compared after alignment)
    for a, b in zip(result.positions, plain.positions, strict=True):
        assert shape_distance(a, b) <= 1e-5 * float(dome.spacing)
    assert np.array_equal(result.gaussian_sign, plain.gaussian_sign)
