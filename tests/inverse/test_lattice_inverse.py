"""Adjoint design of lattices: exact gradients, misfit gradients, targets and round trips."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact import Contact
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.errors import InvalidDesignError, InvalidParameterError
from rotomorph.inverse.adjoint import NotAMinimumError, adjoint, richardson_difference
from rotomorph.inverse.blend import with_settings
from rotomorph.inverse.lattice import (
    SOLVE_OPTIONS,
    Surroundings,
    _Equilibria,
    design_lattice,
    dome,
    height_map,
    lattice_blend,
    misfit_and_gradient,
    saddle,
    shape,
    shape_misfit,
    split,
    surface_misfit,
    surroundings,
)
from rotomorph.inverse.run import lattice_design_file
from rotomorph.io.designfile import ContactModel
from rotomorph.lattice.heating import lattice_gravity
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.objective import RodObjective


@pytest.fixture(scope="module")
def small():
    lat = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    return lat, lattice_blend(lat)


def test_adjoint_gradient_matches_central_differences(small):
    """Modes and speeds: the adjoint gradient against Richardson-extrapolated central
    differences whose perturbed equilibria are solved to a relative residual of 1e-13."""

    lat, blend = small
    eq = _Equilibria(blend)
    p = _relaxed_design(lat, blend)
    for target in (dome(0.04), saddle(0.04)):
        eq.last = None
        eq.options = SOLVE_OPTIONS
        res = eq(p)
        j, g = misfit_and_gradient(blend, p, res, target, 10.0)
        for e, fd in _central_differences(eq, p, res, target).items():
            assert g[e] == pytest.approx(fd, rel=1e-5, abs=1e-12 * abs(j))


def _relaxed_design(lat, blend):
    """Relaxed modes near the lattice's pattern and random speeds (mm/s)."""
    rng = np.random.default_rng(3)
    base = np.array([1.0 if m == "expanding" else -1.0 for m in lat.edge_mode])
    c = np.clip(0.7 * base + rng.uniform(-0.1, 0.1, blend.n_edges), -1, 1)
    return np.concatenate([c, rng.uniform(1.0, 2.5, blend.n_edges)])


#: Relative residual of the perturbed equilibria and the step of the central differences.
FD_RTOL, FD_STEP = 1e-13, 1e-3


def _central_differences(eq, p, res, target, residuals=None):
    """dJ/dp of two modes and two speeds by Richardson-extrapolated central differences, the
    perturbed equilibria warm-started from ``res`` and solved to a relative residual
    ``FD_RTOL`` (the residuals they reached are appended to ``residuals``)."""
    eq.options = NewtonOptions(rtol=FD_RTOL, max_iterations=300)

    def shifted(e, h):
        pp = p.copy()
        pp[e] += h
        eq.last = (p, res.state)
        out = eq(pp)
        if residuals is not None:
            residuals.append(out.residual)
        return surface_misfit(out.positions, target, 10.0)[0]

    n = eq.blend.n_edges
    return {
        e: richardson_difference(lambda h, e=e: shifted(e, h), FD_STEP)
        for e in (0, 9, n + 1, n + 8)
    }


def _difference_error_bound(blend, p, res, target, env, residual):
    """Largest error of :func:`_central_differences` that the perturbed solves' residual allows.

    An equilibrium solved to a weighted residual ``|w g| <= residual F`` (``F`` the solve's
    force scale, ``w`` its weights) is off by ``dx = H^-1 g``, which changes the misfit by
    ``dJ/dx . dx = lambda^T g``, at most ``eps = |lambda / w| residual F`` (``lambda`` the
    adjoint vector). A central difference at step ``h`` is then off by at most ``eps / h``;
    the Richardson extrapolation ``(4 d(h/2) - d(h)) / 3`` by ``(8 + 1) eps / (3 h) = 3 eps / h``
    (``(4 d(h) - d(2h)) / 3`` by half that). ``F`` is taken at ``p``; the perturbed designs'
    differ from it by less than 1e-4 relative.
    """
    c, v = split(blend, p)
    model = blend.rod(c, v)
    obj = RodObjective(model, res.state, Supports(), env.loads or Loads(), env.contact)
    _, gx, _ = surface_misfit(res.positions, target, 10.0)
    lay = model.layout
    dj_dx = np.zeros(lay.count)
    dj_dx[(lay.pos[:, None] + np.arange(3)).ravel()] = gx.ravel()
    lam = adjoint(model, res.state, dj_dx, loads=env.loads, contact=env.contact).adjoint
    eps = np.linalg.norm(lam[obj.free] / obj.weights()) * residual * obj.force_scale
    return 3.0 * eps / FD_STEP


def test_adjoint_gradient_with_active_contact_matches_central_differences(small):
    """A lattice resting on the floor under its buoyant weight: the barrier's Hessian is part
    of the adjoint system (without it the rod Hessian alone is not that of a minimum); checked
    against Richardson-extrapolated central differences of tightly solved perturbed
    equilibria. The weight is that of the printed filament: speeds change the natural rest
    lengths but not the mass, so the weight adds no term to dg/dp."""
    lat, blend = small
    env = surroundings(blend, contact=True, floor=True, gravity=lattice_gravity(lat))
    assert env.contact is not None and env.contact.stiffness is not None  # fixed barrier
    eq = _Equilibria(blend, env=env)
    p = _relaxed_design(lat, blend)
    res = eq(p)
    # the equilibrium the gradient is taken at, solved as tightly as the perturbed ones
    eq.options, eq.last = NewtonOptions(rtol=FD_RTOL, max_iterations=300), (p, res.state)
    res = eq(p)
    assert res.contact.active_contacts(res.state) > 0  # it rests on the floor
    target = dome(0.04)
    j, g = misfit_and_gradient(blend, p, res, target, 10.0, env=env)
    with pytest.raises(NotAMinimumError):  # the rod Hessian without the barrier's
        misfit_and_gradient(blend, p, res, target, 10.0)
    # the same barrier and equilibrium, the weight left out of the adjoint's loads
    _, g_no_weight = misfit_and_gradient(blend, p, res, target, 10.0, env=Surroundings(env.contact))
    residuals = [res.residual]
    fds = _central_differences(eq, p, res, target, residuals)
    for e, fd in fds.items():
        assert g[e] == pytest.approx(fd, rel=1e-5, abs=1e-12 * abs(j))
    # The speed gradient is checked against what the differences resolve (their error bound
    # from the solve tolerance): a weight that followed the natural rest lengths would shift it
    # by ~1e-4 of its size, outside that bound. At a fixed equilibrium a constant weight does
    # not enter the adjoint system, so leaving it out changes nothing.
    bound = _difference_error_bound(blend, p, res, target, env, max(FD_RTOL, *residuals))
    speeds = [e for e in fds if e >= blend.n_edges]  # speeds change the rest lengths
    assert all(abs(g[e] - fds[e]) <= bound for e in speeds)
    np.testing.assert_allclose(g_no_weight, g, rtol=1e-12, atol=1e-15 * abs(j))


def test_contact_settings_are_checked(small):
    lat, blend = small
    with pytest.raises(InvalidParameterError, match="gravity"):
        surroundings(blend, gravity=lattice_gravity(lat))
    with pytest.raises(InvalidParameterError, match="friction"):
        surroundings(blend, contact=Contact(radius=lat.radius, friction=0.3))


def test_design_is_printable_verified_and_written_as_a_design_file(tmp_path):
    start = sinusoidal_lattice(
        n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6, pattern="dome", centre="interior"
    )
    des = design_lattice(start, dome(0.1), max_iterations=3, speed_resolution=0.1)
    finite = des.objective_history[np.isfinite(des.objective_history)]
    assert finite.min() < finite[0]  # the optimiser improved on the start
    assert set(np.unique(des.modes)) <= {-1.0, 1.0}
    # printable speeds: multiples of the resolution inside the measured range
    assert np.allclose(des.speeds / 0.1, np.round(des.speeds / 0.1))
    assert des.speeds.min() >= 0.25 and des.speeds.max() <= 3.0
    assert des.stable
    file = lattice_design_file(des, "dome")
    assert file.lattice is not None and file.lattice.pattern == "custom"
    assert [m == "expanding" for m in file.lattice.edge_modes] == list(des.modes > 0)
    assert file.contact is None
    on_floor = ContactModel(floor=True, gravity=True)
    assert lattice_design_file(des, "dome", on_floor).contact == on_floor  # simulate's physics
    # the written design is the verified one, speeds included
    assert file.lattice.to_lattice().edge_mode == des.lattice.edge_mode
    assert np.allclose(file.lattice.to_lattice().speeds, des.speeds)
    # validate, simulate and gcode accept it unchanged
    from rotomorph.cli import main
    from rotomorph.io.designfile import save_design

    path = save_design(file, tmp_path / "dome.toml")
    assert main(["validate", str(path)]) == 0
    assert main(["gcode", str(path), "-o", str(tmp_path / "dome.gcode")]) == 0
    assert main(["simulate", str(path), "-o", str(tmp_path / "run"), "--steps", "4"]) == 0


def test_bad_lattice_targets_have_clear_errors(small):
    lat, _ = small
    with pytest.raises(InvalidDesignError, match="close on itself"):
        design_lattice(lat, dome(1.0))
    x = np.linspace(-3, 3, 6)
    with pytest.raises(InvalidDesignError, match="extend the grid"):
        design_lattice(lat, height_map(x, x, np.zeros((6, 6))))
    x = np.linspace(-8, 8, 6)
    with pytest.raises(InvalidDesignError, match="more than the lattice size"):
        design_lattice(lat, height_map(x, x, np.outer(x, x)))
    with pytest.raises(InvalidDesignError, match="positive curvature"):
        dome(-0.1)
    with pytest.raises(InvalidParameterError, match="speed_range"):
        design_lattice(lat, dome(0.05), speed_range=(2.0, 1.0))
    with pytest.raises(InvalidParameterError, match="speed_resolution"):
        design_lattice(lat, dome(0.05), speed_resolution=0.0)


def test_blend_at_printable_settings_is_the_forward_actuation(small):
    """At printable modes and any speeds the blend gives exactly the natural values the
    forward model builds from the print programs."""
    from rotomorph.lattice.actuation import ProgramActuation, default_stiffness
    from rotomorph.lattice.model import lattice_model

    lat, blend = small
    act = ProgramActuation()
    stiffness, fm = default_stiffness(act)
    rng = np.random.default_rng(5)
    for _ in range(2):
        modes = rng.choice([-1.0, 1.0], blend.n_edges)
        speeds = rng.uniform(0.25, 3.0, blend.n_edges)
        printed = with_settings(lat, modes, speeds)
        ref = act.natural(lattice_model(printed, stiffness=stiffness, filament_model=fm), act.end)
        k, rest = blend.natural(modes, speeds)
        assert np.allclose(k, np.stack(ref.integrated_natural(), axis=1), atol=1e-12)
        assert np.allclose(rest, ref.rest_length, rtol=1e-13)
        assert np.allclose(ref.bending_stiffness1, blend.model.bending_stiffness1)


def test_shape_misfit_gradient_and_rigid_invariance():
    rng = np.random.default_rng(7)
    y = rng.normal(size=(30, 3))
    x = y + 0.05 * rng.normal(size=(30, 3))
    j, g = shape_misfit(x, y, 4.0)
    rot = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    assert shape_misfit(x @ rot.T + 2.0, y, 4.0)[0] == pytest.approx(j, rel=1e-12)
    h = 1e-6
    for i, k in [(0, 0), (7, 2), (29, 1)]:
        xp, xm = x.copy(), x.copy()
        xp[i, k] += h
        xm[i, k] -= h
        fd = (shape_misfit(xp, y, 4.0)[0] - shape_misfit(xm, y, 4.0)[0]) / (2 * h)
        assert g[i, k] == pytest.approx(fd, rel=1e-6)


def test_round_trip_recovers_a_hidden_program_from_the_shape():
    """A lattice printed with a hidden pattern and hidden speeds is heated by the forward
    simulation; a program recovered from its node positions alone, starting from a uniform
    guess, heats (forward simulation again) into the same shape within 2 % of the size."""
    from rotomorph.lattice.heating import heat_lattice

    start = sinusoidal_lattice(n=3, spacing=5.0, amplitude=1.25, ghost_nodes=6)
    rng = np.random.default_rng(11)
    m = len(start.edge_chains)
    hidden = with_settings(start, rng.choice([-1.0, 1.0], m), rng.uniform(0.8, 3.0, m).round(2))
    goal = heat_lattice(hidden, steps=8).positions[-1]
    size = start.spacing * (start.n - 1)
    des = design_lattice(start, shape(goal), nodes="all", max_iterations=15)
    again = heat_lattice(des.lattice, steps=8).positions[-1]
    rms = np.sqrt(2.0 * shape_misfit(again, goal, size)[0]) * size
    assert rms / size < 0.02


def test_richardson_difference_picks_the_consistent_steps():
    exact = np.cos(0.3)
    assert richardson_difference(lambda h: np.sin(0.3 + h), 1e-2) == pytest.approx(exact, rel=1e-9)
    # noise that only the smallest step feels: the coarse pair is chosen
    noisy = lambda h: np.sin(0.3 + h) + (1e-9 * np.sign(h) if abs(h) < 1e-3 else 0.0)  # noqa: E731
    assert richardson_difference(noisy, 1e-3) == pytest.approx(exact, rel=1e-9)
