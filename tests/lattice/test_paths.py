"""Path check of a heating ramp: a multistable lattice keeps the end state lower in energy."""

from __future__ import annotations

import time
from types import SimpleNamespace

import numpy as np
import pytest

import rotomorph.lattice.heating as heating
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import ConvergenceError, InvalidParameterError
from rotomorph.lattice import heat_lattice
from rotomorph.lattice.heating import _gaps_per_step, lattice_gravity
from rotomorph.lattice.paths import (
    PathCheck,
    check_factor,
    choose_end,
    per_row,
    shape_distance,
    sub_stepped,
)


def test_sub_stepped_keeps_the_requested_values_exactly():
    values = np.linspace(25.0, 175.0, 9)
    fine = sub_stepped(values, 3)
    assert len(fine) == 25 and np.array_equal(fine[::3], values)
    assert np.all(np.diff(fine) > 0)
    np.testing.assert_allclose(fine, np.linspace(25.0, 175.0, 25), rtol=1e-15, atol=1e-12)


def test_shape_distance_ignores_rigid_motion():
    rng = np.random.default_rng(1)
    a = rng.normal(size=(40, 3))
    c, s = np.cos(0.7), np.sin(0.7)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    assert shape_distance(a, a @ rot.T + [3.0, -1.0, 2.0]) < 1e-12
    b = a.copy()
    b[5] += [0.0, 0.0, 0.1]
    assert 0.05 < shape_distance(a, b) < 0.1


def test_choose_end():
    same = choose_end((0.2, 0.1), (True, True), True, 2)
    assert same.kept == "steps" and same.same_state and "same state" in same.note
    lower = choose_end((0.222, 0.214), (True, True), False, 2)
    assert lower.kept == "sub-steps" and not lower.same_state
    assert "multistable" in lower.note and "(sub-steps)" in lower.note
    assert choose_end((0.214, 0.222), (True, True), False, 2).kept == "steps"
    unstable = choose_end((0.3, 0.1), (True, False), False, 2)
    assert unstable.kept == "steps" and "sub-stepped one is not certified stable" in unstable.note
    only = choose_end((0.1, 0.3), (False, True), False, 2)  # only the second end is stable
    assert only.kept == "sub-steps" and "requested one is not certified stable" in only.note
    # different shapes of equal energy (a flat valley, a symmetric partner): a tie, never a
    # switch on round-off, whichever end is lower by it
    for e2 in (0.19591544551155562, 0.19591544551154):
        tie = choose_end((0.19591544551155, e2), (True, True), False, 2)
        assert tie.tie and tie.kept == "steps" and not tie.same_state
        assert "same total energy" in tie.note
    assert not choose_end((0.2, 0.2 * (1 - 1e-8)), (True, True), False, 2).tie
    failed = choose_end((0.3, np.nan), (True, False), False, 2)
    assert failed.kept == "steps" and "failed" in failed.note


def test_choose_end_never_keeps_an_inadmissible_end():
    # the sub-stepped end is lower, but its stack's layers interpenetrate: never chosen
    lower = choose_end((0.222, 0.214), (True, True), False, 2, admissible=(True, False))
    assert lower.kept == "steps" and lower.admissible == (True, False)
    assert "sub-stepped one is not admissible" in lower.note
    # the requested end is inadmissible, the sub-stepped one admissible (even if higher)
    other = choose_end((0.1, 0.3), (True, True), False, 2, admissible=(False, True))
    assert other.kept == "sub-steps" and "requested one is not admissible" in other.note
    assert other.stable == (True, True)  # stability is reported as it was found


@pytest.mark.parametrize("bad", [0, 9, 1.5, 2.0, True, None, "2"])
def test_check_factor_refuses_anything_but_small_integers(bad):
    with pytest.raises(InvalidParameterError, match="path_check"):
        check_factor(bad)
    assert check_factor(np.int64(3)) == 3


def test_gaps_are_put_in_the_row_of_the_step_they_lead_to():
    up = np.array([0.0, 1.0, 2.0, 3.0])
    gaps = _gaps_per_step({0.5: -0.1, 1.0: 0.2, 2.5: 0.3, 2.75: -0.4}, up)
    np.testing.assert_array_equal(np.isnan(gaps), [True, False, True, False])
    assert gaps[1] == -0.1 and gaps[3] == -0.4  # the lowest gap within a step
    down = up[::-1]
    gaps = _gaps_per_step({2.5: -0.2, 0.0: 0.1}, down)
    assert gaps[1] == -0.2 and gaps[3] == 0.1 and np.isnan(gaps[[0, 2]]).all()


def _small():
    return sinusoidal_lattice(3, 5.0, 1.25, 6, "dome")


def test_rows_take_the_most_halvings_and_the_summed_time_of_their_sub_steps():
    steps = [
        SimpleNamespace(halvings=h, wall_time=t)
        for h, t in [(0, 1.0), (2, 0.5), (1, 0.25), (0, 2.0)]
    ]
    halvings, wall = per_row(steps, 2)
    assert list(halvings) == [0, 2, 1]
    np.testing.assert_allclose(wall, [0.0, 1.5, 2.25])
    halvings, wall = per_row(steps, 1)
    assert list(halvings) == [0, 0, 2, 1, 0]
    np.testing.assert_allclose(wall, [0.0, 1.0, 0.5, 0.25, 2.0])


def test_a_halved_ramp_step_shows_in_its_row(monkeypatch):
    """A ramp step that fails once and succeeds halved: its row records one halving (and the
    midpoint's iterations), the others none; the sub-stepped-ramp test above sees only rows
    without halvings, where any aggregation (or none) gives zeros."""
    real = heating.continuation

    def first_try_fails(solve, params, initial, **kw):  # type: ignore[no-untyped-def]
        failed: list[float] = []

        def flaky(p, state):  # type: ignore[no-untyped-def]
            if p == params[1] and not failed:
                failed.append(p)
                raise ConvergenceError("injected")
            return solve(p, state)

        return real(flaky, params, initial, **kw)

    plain = heat_lattice(_small(), steps=2)
    monkeypatch.setattr(heating, "continuation", first_try_fails)
    res = heat_lattice(_small(), steps=2)
    assert plain.halvings.tolist() == [0, 0, 0] and res.halvings.tolist() == [0, 0, 1]
    assert res.iterations[1] == plain.iterations[1]
    assert res.iterations[2] > plain.iterations[2]  # the midpoint's solve counts toward it
    # the same end state (free lattices drift rigidly by a step's history)
    assert shape_distance(res.positions[-1], plain.positions[-1]) < 1e-4  # mm
    assert res.energy[-1] == pytest.approx(plain.energy[-1], rel=1e-9)


def test_path_check_records_both_ramps():
    plain = heat_lattice(_small(), steps=2)
    res = heat_lattice(_small(), steps=2, path_check=2)
    four = heat_lattice(_small(), steps=4)
    check = res.path_check
    assert check is not None and len(res.parameter) == 3
    assert check.energy == pytest.approx((plain.energy[-1], four.energy[-1]), rel=1e-12, abs=1e-15)
    assert check.discarded_iterations == (
        four.total_iterations if check.kept == "steps" else plain.total_iterations
    )
    assert plain.path_check is None


def test_kept_sub_stepped_ramp_is_sampled_at_the_requested_steps(monkeypatch):
    def prefer_sub_steps(energy, stable, same, factor, admissible=(True, True)):  # type: ignore[no-untyped-def]
        return PathCheck(factor, energy, stable, "sub-steps", False)

    monkeypatch.setattr(heating, "choose_end", prefer_sub_steps)
    res = heat_lattice(_small(), steps=2, path_check=2)
    fine = heat_lattice(_small(), steps=4)
    np.testing.assert_array_equal(res.parameter, fine.parameter[::2])
    np.testing.assert_allclose(res.positions, fine.positions[::2], atol=1e-12)
    np.testing.assert_allclose(res.energy, fine.energy[::2], rtol=1e-12)
    np.testing.assert_allclose(res.lowest_eigenvalue[1:], fine.lowest_eigenvalue[2::2], rtol=1e-9)
    assert res.stable == fine.stable[::2]
    assert res.total_iterations == fine.total_iterations
    assert list(res.iterations[1:]) == [
        fine.iterations[1] + fine.iterations[2],
        fine.iterations[3] + fine.iterations[4],
    ]
    assert list(res.halvings[1:]) == [max(fine.halvings[1:3]), max(fine.halvings[3:5])]


def test_a_failed_second_ramp_keeps_the_first(monkeypatch):
    calls = []
    real = heating.continuation

    def second_fails(*args, **kwargs):  # type: ignore[no-untyped-def]
        calls.append(1)
        if len(calls) == 2:
            time.sleep(0.05)  # what the failed ramp cost before it failed
            raise ConvergenceError("injected")
        return real(*args, **kwargs)

    plain = heat_lattice(_small(), steps=2)
    monkeypatch.setattr(heating, "continuation", second_fails)
    res = heat_lattice(_small(), steps=2, path_check=2)
    assert res.path_check is not None and res.path_check.kept == "steps"
    assert "failed" in res.path_check.note
    assert res.path_check.discarded_wall_time >= 0.05  # the failed ramp's time is recorded
    np.testing.assert_array_equal(res.iterations, plain.iterations)
    np.testing.assert_allclose(res.positions, plain.positions, atol=1e-12)


def test_path_check_with_friction_is_refused():
    lat = _small()
    with pytest.raises(InvalidParameterError, match="path_check"):
        heat_lattice(lat, steps=1, floor=True, gravity=lattice_gravity(lat), friction=0.3,
                     path_check=2)  # fmt: skip


def test_best_rotation_recovers_a_rotation_and_never_reflects():
    from scipy.spatial.transform import Rotation

    from rotomorph.geometry import best_rotation

    rng = np.random.default_rng(3)
    p = rng.normal(size=(20, 3))
    p -= p.mean(axis=0)
    r = Rotation.from_rotvec([0.3, -1.1, 0.7]).as_matrix()
    np.testing.assert_allclose(best_rotation(p, p @ r.T), r, atol=1e-12)
    mirrored = best_rotation(p, p * [1.0, 1.0, -1.0])  # no rotation maps p onto its mirror
    assert np.linalg.det(mirrored) == pytest.approx(1.0)
