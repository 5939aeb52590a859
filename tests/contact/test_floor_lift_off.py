"""A lattice resting on the floor under its weight: on a rigid floor the flat resting state is a
strict local minimum at every actuation (lifting costs weight × height to first order, the
bending energy released is second order), so following it continuously keeps a dome flat long
after a lifted dome is lower in energy (here to the end of the ramp; with a softer barrier
until its finite stiffness lets go, with a snap); the default ramp also looks for a lifted
equilibrium and takes it when its total energy is lower."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.analysis.curvature import fit_quadratic_surface
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidParameterError
from rotomorph.lattice.actuation import CurvatureScaling
from rotomorph.lattice.heating import (
    RAMP_OPTIONS,
    heat_lattice,
    lattice_gravity,
    perturbed_state,
    symmetry_breaking,
)
from rotomorph.lattice.model import lattice_model
from rotomorph.lattice.published import (
    FRICTION,
    GRAVITY,
    LOGGED_STRETCH,
    YOUNGS_MODULUS,
    published_actuation,
    published_gravity,
    published_lattice,
)
from rotomorph.solve.static import solve_static

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
    lifted = np.flatnonzero(rest.floor_lift > 2.0 * dome.radius)
    late = int(lifted[0]) if len(lifted) else len(rest.floor_lift)  # (here: never)
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
    assert float(best.min_clearance.min()) > 0.995  # pressed contacts: within 0.5 %


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


def test_no_probe_where_it_would_move_supports():
    """The probe moves the lattice rigidly: not with supports (they would move with it); such
    ramps are continuous."""
    lat = sinusoidal_lattice(n=2, ghost_nodes=2, pattern="dome")
    res = heat_lattice(
        lat,
        actuation=ACT,
        steps=1,
        floor=True,
        gravity=lattice_gravity(lat),
        supports="pinned-centre",
    )
    assert res.lift_energy_gap is None


def test_the_probe_runs_with_friction():
    """With friction the probe compares potential energies (lagged friction left out of
    both), so a ramp with friction looks for a lifted state too (it did not before)."""
    lat = sinusoidal_lattice(n=2, ghost_nodes=2, pattern="dome")
    res = heat_lattice(
        lat, actuation=ACT, steps=1, floor=True, gravity=lattice_gravity(lat), friction=0.3
    )
    assert res.lift_energy_gap is not None and res.lift_energy_gap.shape == (2,)


#: A weight 1000 times below the authors' logged one (w l³/B ≈ 1e-5): negligible.
NEGLIGIBLE = 1e-3 * GRAVITY


@pytest.fixture(scope="module")
def authors_free_saddle():
    """The authors' lattice at their logged stretch, weightless, away from any floor."""
    lat = published_lattice()
    lm = lattice_model(lat, stiffness="paper", youngs_modulus=YOUNGS_MODULUS)
    model = published_actuation(0.0, LOGGED_STRETCH).natural(lm, LOGGED_STRETCH)
    bump = symmetry_breaking(lat, 1e-2 * lat.spacing, 0)
    return solve_static(model, initial=perturbed_state(lm.model, bump), options=RAMP_OPTIONS)


@pytest.mark.parametrize(
    "friction",
    [
        pytest.param(0.0, id="frictionless"),
        # a frictional Newton iteration costs ~15 x a frictionless one (docs/published-simulation)
        pytest.param(FRICTION, id="friction 0.4", marks=pytest.mark.slow),
    ],
)
def test_the_authors_saddle_leaves_the_floor_where_it_is_lower(friction, authors_free_saddle):
    """The authors' saddle set-up (their lattice, edge lists, stretch -0.17, E = 2e11 Pa, their
    floor friction 0.4) under a negligible weight: the flat state on the floor is a strict
    local minimum (the continuous branch stays there), but the free saddle is ~15 % lower in
    total energy and nothing holds it down, so the lowest branch must take it. The probe used
    to give up when the weightless buckling ran out of Newton iterations (about 430 are needed
    from the flat state), and did not run at all with friction."""
    lat = published_lattice()
    kw = dict(
        actuation=published_actuation(0.0, LOGGED_STRETCH),
        steps=1,
        stiffness="paper",
        youngs_modulus=YOUNGS_MODULUS,
        floor=True,
        friction=friction,
        gravity=published_gravity(NEGLIGIBLE),
    )
    res = heat_lattice(lat, **kw)
    assert res.gaussian_sign[-1] == -1 and res.stable[-1] is True
    assert res.floor_lift[-1] > 2.0 * lat.radius
    # it is the free saddle (an independent solve: no floor, no weight, no probe), resting on
    # the floor on a few points
    assert res.energy[-1] == pytest.approx(authors_free_saddle.energy, rel=2e-3)
    assert res.characteristic_curvature[-1] == pytest.approx(
        fit_quadratic_surface(
            authors_free_saddle.positions[lat.branch_indices]
        ).characteristic_curvature,
        rel=1e-2,
    )
    gap = res.lift_energy_gap[-1]
    resting = res.energy[-1] - gap
    assert -0.16 < gap / resting < -0.13  # ~15 % lower than resting flat
    if not friction:
        flat = heat_lattice(lat, branch="continuous", **kw)
        assert flat.gaussian_sign[-1] == 0 and flat.stable[-1] is True
        assert flat.floor_lift[-1] < 2.0 * lat.radius
        assert flat.energy[-1] == pytest.approx(resting, rel=1e-9)


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
    # the same ramp as without refinement, to Newton's tolerance: the contact Hessian's pattern,
    # grown once per network, depends on which ramps ran before this one in the process, so the
    # sums are ordered differently and Newton stops on a neighbouring iterate (seen: 1.2e-10 mm
    # on a 5 mm lattice)
    np.testing.assert_allclose(res.positions, ramps["lowest"].positions, rtol=0, atol=1e-8)
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


def test_the_probe_compares_potential_energies_the_solver_reports():
    """The potential energy the probe evaluates for a resting state with friction is the one
    the solver reports for the same state without friction (same barrier stiffness), and with
    friction the solver's total exceeds it by the lagged friction term (>= 0)."""
    from dataclasses import replace

    from rotomorph.lattice.heating import _potential_energy, contact_settings
    from rotomorph.solve.loads import Loads, Supports

    lat = sinusoidal_lattice(n=2, ghost_nodes=2, pattern="dome")
    lm = lattice_model(lat, stiffness="paper")
    model = CurvatureScaling("swapped").natural(lm, 0.3)
    start = perturbed_state(lm.model, symmetry_breaking(lat, 1e-3 * lat.spacing, 0))
    rough = contact_settings(lat, start.positions, False, True, 0.3)
    slick = replace(rough, friction=0.0)
    loads = Loads(gravity=lattice_gravity(lat))
    res = solve_static(model, Supports(), loads, initial=start, contact=slick)
    assert _potential_energy(model, Supports(), loads, slick, res.state) == pytest.approx(
        res.energy, rel=1e-12
    )
    held = solve_static(model, Supports(), loads, initial=start, contact=rough)
    potential = _potential_energy(model, Supports(), loads, slick, held.state)
    assert held.energy >= potential - 1e-12 * abs(potential)
