"""A lattice resting on the floor under its weight: on a rigid floor the flat resting state is a
strict local minimum at every actuation (lifting costs weight × height to first order, the
bending energy released is second order), so following it continuously keeps a dome flat long
after a lifted dome is lower in energy (here until the barrier's finite stiffness lets go, with
a snap); the default ramp also looks for a lifted equilibrium and takes it when its total
energy is lower."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.heating import heat_lattice, lattice_gravity

ACT = "swapped"  # the paper's in-plane curvature scaling: the flat state is an equilibrium


@pytest.fixture(scope="module")
def dome():
    return sinusoidal_lattice(n=5, ghost_nodes=4, pattern="dome")


@pytest.fixture(scope="module")
def ramps(dome):
    kw = dict(actuation=ACT, steps=8, floor=True, gravity=lattice_gravity(dome))
    return {b: heat_lattice(dome, branch=b, **kw) for b in ("continuous", "lowest")}


def test_the_resting_branch_stays_flat_long_after_the_lifted_one_is_lower(ramps, dome):
    rest, best = ramps["continuous"], ramps["lowest"]
    assert rest.lift_energy_gap is None
    assert all(rest.stable)  # a certified minimum at every step, not a saddle point
    k = int(np.flatnonzero(best.floor_lift > 2.0 * dome.radius)[0])
    late = int(np.flatnonzero(rest.floor_lift > 2.0 * dome.radius)[0])
    assert late >= k + 3  # flat and stable for three more steps
    assert (rest.gaussian_sign[:late] == 0).all()
    assert (rest.energy[k:late] > best.energy[k:late]).all()


def test_the_default_takes_the_lifted_dome_where_it_is_lower_in_energy(ramps, dome):
    rest, best = ramps["continuous"], ramps["lowest"]
    assert best.gaussian_sign[-1] == 1 and all(best.stable)
    k = int(np.flatnonzero(best.floor_lift > 2.0 * dome.radius)[0])
    assert best.first_lift_off() == best.parameter[k]
    gap = best.lift_energy_gap[k]
    assert gap < 0.0 and np.isnan(best.lift_energy_gap[:k]).all()
    # the gap is the difference of the two branches' total energies at that step
    assert best.energy[k] - rest.energy[k] == pytest.approx(gap, rel=1e-6)
    # once lifted, it follows the lifted branch: no more probes, never above the resting one
    assert np.isnan(best.lift_energy_gap[k + 1 :]).all()
    assert (best.energy <= rest.energy + 1e-9 * np.abs(rest.energy).max()).all()
    assert float(best.min_clearance.min()) >= 0.999


def test_a_bad_branch_name_is_refused(dome):
    with pytest.raises(InvalidParameterError, match="branch"):
        heat_lattice(dome, actuation=ACT, steps=1, branch="global")  # type: ignore[arg-type]


def test_a_perfectly_flat_dome_on_the_floor_still_rises(dome):
    """No symmetry-breaking noise: the flat dome on the floor is a minimum of the floor problem
    at every step, and only the lift probe finds the dome."""
    flat = heat_lattice(
        dome, actuation=ACT, steps=8, floor=True, gravity=lattice_gravity(dome), perturbation=0.0
    )
    assert flat.gaussian_sign[-1] == 1 and all(flat.stable)
    assert flat.first_lift_off() is not None


@pytest.mark.parametrize(
    "kw", [{"supports": "pinned-centre"}, {"friction": 0.3}], ids=["supported", "friction"]
)
def test_no_probe_where_it_would_move_supports_or_compare_dissipation(kw):
    """The probe moves the lattice rigidly and compares total energies: not with supports
    (they would move) nor with lagged friction (not a potential); those ramps are continuous."""
    lat = sinusoidal_lattice(n=2, ghost_nodes=2, pattern="dome")
    res = heat_lattice(lat, actuation=ACT, steps=1, floor=True, gravity=lattice_gravity(lat), **kw)
    assert res.lift_energy_gap is None


def test_lift_off_and_weightless_buckling_are_bisected_and_ordered(dome, ramps):
    """The weight delays lift-off: the flat lattice must first buckle without it (the probe
    searches only along an unstable mode), then gain enough to pay for lifting its weight."""
    tol = 0.02
    res = heat_lattice(
        dome,
        actuation=ACT,
        steps=8,
        floor=True,
        gravity=lattice_gravity(dome),
        lift_off_tolerance=tol,
    )
    # the same ramp as without refinement
    np.testing.assert_array_equal(res.positions, ramps["lowest"].positions)
    (lo, hi), (b_lo, b_hi) = res.lift_off_bracket, res.buckling_bracket
    assert 0 < hi - lo <= tol and 0 < b_hi - b_lo <= tol
    k = int(np.flatnonzero(res.floor_lift > 2.0 * dome.radius)[0])
    assert res.parameter[k - 1] <= lo < hi <= res.parameter[k]
    # it buckles (weightless) first, and leaves the floor only a finite step later: just past
    # buckling the energy released (second order in the rise) cannot pay for the weight
    # (first order)
    assert b_hi <= lo
    with pytest.raises(InvalidParameterError, match="lift_off_tolerance"):
        heat_lattice(dome, actuation=ACT, steps=1, lift_off_tolerance=0.0)
