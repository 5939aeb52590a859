"""Lattice designs in the bath: verified by simulate's own ramp, never reached when not
physical, unreached targets measured, the calibration band consistent with the verification."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.inverse import bath as bath_module
from rotomorph.inverse.bath import bath_contact, verify_in_bath
from rotomorph.inverse.blend import with_settings
from rotomorph.inverse.environment import _heated_k, design_band
from rotomorph.inverse.lattice import dome, saddle
from rotomorph.io.designfile import parse_design
from rotomorph.lattice.heating import lattice_buoyancy
from rotomorph.materials.natural import FilamentModel
from rotomorph.simulate.design import simulate_design
from rotomorph.solve.loads import Loads


@pytest.fixture(scope="module")
def printed():
    """A 3 x 3 dome pattern at one speed: it lifts off the bath floor in simulate's ramp."""
    lat = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    modes = np.array([1.0 if m == "expanding" else -1.0 for m in lat.edge_mode])
    return with_settings(lat, modes, np.full(len(modes), 0.5))


@pytest.fixture(scope="module")
def checked(printed):
    return verify_in_bath(printed, dome(0.1).gaussian_curvature, diagnose=True)


def _design_file(lat, contact):
    return parse_design(
        {
            "schema_version": 1,
            "name": "bath",
            "lattice": {
                "n": lat.n,
                "spacing": lat.spacing,
                "amplitude": lat.amplitude,
                "ghost_nodes": lat.ghost_nodes,
                "centre": "interior",
                "pattern": "custom",
                "edge_modes": list(lat.edge_mode),
                "speed": lat.speed,
                "edge_speeds": [float(v) for v in lat.edge_speeds],
                "origin": [20.0, 20.0, 0.0],
            },
            "contact": contact.model_dump(),
        }
    )


def test_verification_is_the_ramp_simulate_runs_on_the_design_file(printed, checked):
    """Referee: rotomorph simulate's own entry point on the design file with the bath table
    ends in the verified state (same ramp, surroundings, lift probe)."""
    sim = simulate_design(_design_file(printed, bath_contact()))
    end = np.asarray(sim.positions[-1]) - np.array([20.0, 20.0, 0.0])
    assert np.max(np.abs(end - checked.positions)) < 1e-9
    assert checked.floor_lift is not None and checked.floor_lift > 2.0 * printed.radius


def test_an_unreached_target_reports_why_with_its_measures(checked):
    """K = 1e-2 asked, far from what this print gives: not reached, and the check says how far
    off, what the same ramp reaches without the weight and the weight-to-bending ratio."""
    assert not checked.reached
    assert checked.error_rel is not None and checked.error_rel > 0.1
    assert "% off" in checked.reason and "without the weight" in checked.reason
    assert checked.weightless_gaussian_curvature is not None
    assert checked.weight_to_bending is not None and checked.weight_to_bending > 0
    record = checked.record()
    assert record["reached"] is False and record["reason"] == checked.reason


def test_an_interpenetrating_verified_state_is_never_reached(printed, checked, monkeypatch):
    """Whatever its K, a verified state with interpenetrating layers is not reached: the same
    ramp judged with a target equal to its own K, once admissible and once with overlaps."""
    own = checked.gaussian_curvature
    clean = verify_in_bath(printed, own, diagnose=False)
    assert clean.admissible and clean.stable and clean.reached, clean.reason
    monkeypatch.setattr(bath_module, "_overlaps", lambda res: 3)
    bad = verify_in_bath(printed, own, diagnose=False)
    assert bad.stack_overlaps == 3 and not bad.admissible and not bad.reached
    assert "interpenetrates" in bad.reason


def test_band_sigma_solves_continue_the_verified_state(printed, checked):
    """The band's warm-started solve at the nominal materials model reproduces the verified
    state's K (so the sigma points differ from it by the calibration only), and the band is
    the central-secant sum over the covariance's directions."""
    contact = checked.result.contact
    loads = Loads(gravity=lattice_buoyancy(printed)(175.0))
    k = _heated_k(printed, FilamentModel(), 175.0, checked.result.states[-1], contact, loads)
    assert k == pytest.approx(checked.gaussian_curvature, rel=1e-5)
    band = design_band(printed, checked)
    assert band.failed == 0 and len(band.sigma_points) == 2 * band.directions >= 2
    pairs = band.sigma_points.reshape(-1, 2)
    sd = np.sqrt(np.sum((0.5 * (pairs[:, 0] - pairs[:, 1])) ** 2))
    assert band.gaussian_curvature_sd == pytest.approx(sd) and sd > 0
    assert "±" in band.text()


def test_bath_default_and_targets(printed):
    """The default surroundings are the bath with the lift probe; saddle targets keep their
    sign in the check."""
    c = bath_contact()
    assert c.self_contact and c.floor and c.gravity and c.branch == "lowest"
    assert c.friction == 0 and c.path_check == 1
    assert saddle(0.05).gaussian_curvature < 0


@pytest.mark.slow
def test_robust_design_minimises_the_expected_error_and_says_what_it_gives_up():
    """The robust choice is the scale of least expected K error over the sigma points, it is
    verified in the bath like the nominal design, and its nominal give-up is the difference
    of the two verified errors."""
    from rotomorph.inverse.environment import design_in_bath

    lat = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    des = design_in_bath(lat, dome(0.1), max_iterations=2, robust=True)
    choice = des.robust
    assert choice is not None and des.bath is not None and des.band is not None
    assert choice.scale == min(choice.expected_error, key=choice.expected_error.get)
    assert choice.nominal_error_robust == des.bath.error_rel
    if choice.gives_up is not None:
        assert choice.gives_up == pytest.approx(
            choice.nominal_error_robust - choice.nominal_error_nominal
        )
    assert des.achieved_gaussian_curvature == des.bath.gaussian_curvature
    assert set(choice.record()) >= {"strength_scale", "gives_up_nominally"}


def _in_the_bath(lat):
    """design_lattice's physics of the bath at 175 °C: the printed stack's contact, the floor,
    the buoyant weight, the lowest branch."""
    from rotomorph.contact import Contact
    from rotomorph.inverse.environment import _program
    from rotomorph.lattice.admissibility import lattice_stack

    return dict(
        actuation=_program(175.0),
        contact=Contact(radius=lat.radius, self_contact=True, stack=lattice_stack(lat)),
        floor=True,
        gravity=lattice_buoyancy(lat)(175.0),
        branch="lowest",
    )


@pytest.mark.slow
def test_the_judge_restarts_the_optimiser_on_its_branch_and_never_passes_an_overlap(
    monkeypatch,
):
    """With a judge (simulate's ramp) whose every verdict interpenetrates, the starting
    pattern and JUDGE_ROUNDS optimised designs are judged and none is reached; the solves
    after each judgement start from the state that verdict verified; the design returned is
    the best judged optimised one, with its verdict."""
    from rotomorph.inverse import lattice as lattice_module
    from rotomorph.inverse.lattice import JUDGE_ROUNDS, _verdict_rank, design_lattice

    lat = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    target = dome(0.1)
    monkeypatch.setattr(bath_module, "_overlaps", lambda res: 3)
    verdicts = []

    def judge(printed):
        v = verify_in_bath(printed, target.gaussian_curvature, diagnose=False)
        verdicts.append((np.asarray(printed.edge_speeds, dtype=float), v))
        return v

    starts = []

    class Spy(lattice_module._Equilibria):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            starts.append((len(verdicts), self.heated))

    monkeypatch.setattr(lattice_module, "_Equilibria", Spy)
    des = design_lattice(
        lat,
        target,
        **_in_the_bath(lat),
        max_iterations=2,
        judge=judge,
    )
    assert des.judge_rounds == len(verdicts) == 1 + JUDGE_ROUNDS
    assert all(not v.reached and not v.admissible for _, v in verdicts)
    assert des.reached is False and des.bath is not None and not des.bath.admissible
    kept = min(verdicts[1:], key=lambda t: _verdict_rank(t[1]))
    assert des.bath is kept[1] and np.array_equal(des.speeds, kept[0])
    # after judgement k, the solves start from the state that verdict verified
    for k in range(1, len(verdicts)):
        after = [heated for n, heated in starts if n == k]
        assert after, f"no restart after judgement {k}"
        p = np.concatenate([des.modes, des.speeds])
        assert all(h is not None and h(p) is verdicts[k - 1][1].result.states[-1] for h in after)


def test_a_start_the_judge_finds_reached_is_returned_as_it_is():
    """The starting pattern is judged first: asked for the K its own ramp gives, the design
    is that pattern at its own (printable) speeds, reached, with no optimiser iteration."""
    from rotomorph.inverse.lattice import SurfaceTarget, design_lattice

    lat = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    modes = np.array([1.0 if m == "expanding" else -1.0 for m in lat.edge_mode])
    own = verify_in_bath(with_settings(lat, modes, lat.speeds), None, diagnose=False)
    k = own.gaussian_curvature
    base = dome(float(np.sqrt(k)))
    target = SurfaceTarget("dome", base.height, k, "own K")
    des = design_lattice(
        lat,
        target,
        **_in_the_bath(lat),
        judge=lambda printed: verify_in_bath(printed, k, diagnose=False),
    )
    assert des.reached and des.judge_rounds == 1 and des.iterations == 0
    assert np.array_equal(des.modes, modes) and np.allclose(des.speeds, lat.speeds)
    assert des.bath is not None and des.bath.error_rel == pytest.approx(0.0, abs=1e-9)
