"""Contact against exact answers: a beam pressed onto a crossing rod, a filament on the floor."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.contact import (
    Contact,
    ContactPotential,
    Cylinder,
    Floor,
    InfeasibleContactError,
    Sphere,
)
from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.static import solve_static

R = 0.5  # filament radius (mm)
E = 1.0  # modulus (MPa)


def _beam_on_rod(load_factor: float, length: float = 40.0, gap: float = 0.2):
    """Simply supported beam B (41 nodes, along x) above a fixed rod A (along y) crossing it at
    mid-span, centre lines 2R + gap apart; a mid-span load ``load_factor`` times the load that
    closes the gap. B's axial stiffness is 1 % of E A: with both ends pinned, the membrane
    tension of an inextensible beam would add ~ 1.8 (gap/R)^2 = 28 % to its stiffness; at 1 % it
    adds 0.3 %, the roller support beam theory assumes."""
    nb, na = 41, 11
    xb = np.linspace(-length / 2, length / 2, nb)
    beam = np.stack([xb, 0 * xb, np.full(nb, 2 * R + gap)], 1)
    ya = np.linspace(-5.0, 5.0, na)
    rod = np.stack([0 * ya, ya, 0 * ya], 1)
    chain = lambda k, off: off + np.stack([np.arange(k - 1), np.arange(1, k)], 1)  # noqa: E731
    net = Network(np.vstack([beam, rod]), np.vstack([chain(nb, 0), chain(na, nb)]))
    EI = E * np.pi * R**4 / 4
    model = Model(net, EI, EI, EI / 1.5, 1e-2 * E * np.pi * R**2)
    supports = Supports(
        pinned_nodes=(0, nb - 1, *range(nb, nb + na)),
        fixed_twist_edges=(0, *range(nb - 1, nb + na - 2)),
    )
    closing = 48 * EI * gap / length**3
    loads = Loads(forces=((nb // 2, (0.0, 0.0, -load_factor * closing)),))
    return model, supports, loads, closing, nb


@pytest.mark.parametrize("factor", [1.2, 1.5, 3.0, 6.0])
def test_beam_pressed_on_crossing_rod_carries_load_minus_spring_force(factor):
    """At the default contact settings, from 1.2 x the closing load on: the contact force is
    P - 48 EI delta0 / L^3 within 2 % and the centre lines are r_a + r_b apart within 0.5 %
    (the beam's deflection is the gap: 1 % of the gap is 5 % of the force at 1.2 x)."""
    model, supports, loads, closing, nb = _beam_on_rod(factor)
    res = solve_static(model, supports, loads, contact=Contact(radius=R))
    forces = res.contact.forces(res.positions)
    force = forces[:nb, 2].sum()
    expected = factor * closing - closing  # P - 48 EI delta0 / L^3
    assert force == pytest.approx(expected, rel=0.02)
    # the rod pushes the beam up by exactly what it pushes itself down
    assert forces[nb:, 2].sum() == pytest.approx(-force, rel=1e-9)
    assert 1.0 - 5e-3 < res.contact.clearance(res.positions) <= 1.0
    assert res.contact.active_contacts(res.positions) > 0


@pytest.mark.parametrize("factor", [0.5, 0.95])
def test_beam_below_the_closing_load_bends_freely(factor):
    """Below the closing load nothing touches and nothing pushes: the barrier acts only once
    the surfaces touch (at 0.95 x they are 1 % of the gap, 0.002 mm, apart)."""
    model, supports, loads, _, nb = _beam_on_rod(factor)
    res = solve_static(model, supports, loads, contact=Contact(radius=R))
    deflection = 2 * R + 0.2 - res.positions[nb // 2, 2]
    assert deflection == pytest.approx(0.2 * factor, rel=0.01)  # P L^3 / 48 EI
    assert res.contact.active_contacts(res.positions) == 0
    assert np.all(res.contact.forces(res.positions) == 0.0)


def test_a_barrier_outside_the_contact_distance_makes_the_filaments_thicker():
    """``Contact(offset=0)`` keeps the surfaces strictly apart: the pressed contact settles
    up to the activation distance outside r_a + r_b, and at 1.2 x the closing load the contact
    force is too high by several per cent (what the default's offset removes)."""
    model, supports, loads, closing, nb = _beam_on_rod(1.2)
    res = solve_static(model, supports, loads, contact=Contact(radius=R, offset=0.0))
    force = res.contact.forces(res.positions)[:nb, 2].sum()
    assert force > 1.2 * (0.2 * closing)
    dhat = res.contact.dhat
    assert 1.0 < res.contact.clearance(res.positions) < 1.0 + dhat / (2 * R)


def _filament(height: float, n: int = 21):
    x = np.linspace(0.0, 10.0, n)
    pts = np.stack([x, 0.3 * np.sin(x / 3), np.full(n, height)], 1)
    A, I = np.pi * R**2, np.pi * R**4 / 4
    return Model.chain(
        pts,
        bending_stiffness1=E * I,
        bending_stiffness2=E * I,
        twist_stiffness=E * I / 1.5,
        axial_stiffness=E * A,
    ), pts


def test_filament_rests_on_floor_with_reaction_equal_to_buoyant_weight():
    model, pts = _filament(1.2 * R)
    gravity = Gravity(density=1.2, area=np.pi * R**2, fluid_density=0.97)
    res = solve_static(model, loads=Loads(gravity=gravity), contact=Contact(R, (Floor(),)))
    assert res.residual < 1e-8
    lengths = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    # buoyant weight by hand (N): (1.2 - 0.97) g/cm^3 = 0.23e-6 kg/mm^3, times area, length, g
    weight = 0.23e-6 * np.pi * R**2 * float(lengths.sum()) * 9.80665
    reaction = res.contact.forces(res.positions).sum(axis=0)
    assert reaction[2] == pytest.approx(weight, rel=1e-6)
    (on_floor,) = res.contact.obstacle_forces(res.positions)
    assert on_floor == pytest.approx(-reaction, rel=1e-9, abs=1e-15)
    assert np.allclose(reaction[:2], 0.0)
    # the nodes rest in the barrier's zone, which starts where they touch: pressed by their
    # weight, within 0.5 % of a radius of it
    heights = res.positions[:, 2] - R
    assert np.all(heights < 0) and np.all(heights > -5e-3 * R)
    # frictionless floor: the in-plane rigid motions were removed, not pinned by a support
    assert np.allclose(res.positions[:, :2].mean(0), pts[:, :2].mean(0), atol=1e-9)


def test_contracting_filament_keeps_its_printed_weight():
    """Mass is conserved: a filament whose natural rest length shrinks by 30 % (an LCE
    contracting) still presses on the floor with the weight of what was printed."""
    model, pts = _filament(1.2 * R)
    shrunk = model.with_natural(rest_length=0.7 * np.asarray(model.rest_length))
    gravity = Gravity(density=1.2, area=np.pi * R**2, fluid_density=0.97)
    res = solve_static(shrunk, loads=Loads(gravity=gravity), contact=Contact(R, (Floor(),)))
    printed = float(
        (gravity.line_weight(len(pts) - 1) * np.linalg.norm(np.diff(pts, axis=0), axis=1)).sum()
    )
    reaction = res.contact.forces(res.positions).sum(axis=0)
    # (the shrunk rod carries an axial force: force balance to the solve tolerance, 1e-4; the
    # weight of the natural rest length would be 30 % short)
    assert reaction[2] == pytest.approx(printed, rel=1e-4)


def test_free_body_without_floor_under_gravity_is_refused():
    model, _ = _filament(1.2 * R)
    gravity = Gravity(density=1.2, area=np.pi * R**2, fluid_density=0.97)
    with pytest.raises(InvalidParameterError, match="free body"):
        solve_static(model, loads=Loads(gravity=gravity), contact=Contact(R))


def test_interpenetrating_start_is_refused():
    model, _ = _filament(0.8 * R)
    with pytest.raises(InfeasibleContactError, match="interpenetrate"):
        solve_static(model, Supports(pinned_nodes=(0,)), contact=Contact(R, (Floor(),)))


def test_step_bound_stops_a_tunnelling_step():
    """Two crossing segments 1.1 apart (contact at 1.0, the barrier infinite 0.01 inside it);
    the step moves one 3 mm through the other, whose end point is again clear: the bound stops
    it before the barrier's wall."""
    net = Network([[-1, 0, 0], [1, 0, 0], [0, -1, 1.1], [0, 1, 1.1]], [[0, 1], [2, 3]])
    pot = ContactPotential(Contact(radius=0.5, activation_distance=0.01), net)
    assert pot.offset == 0.01
    x = net.nodes.copy()
    dx = np.zeros_like(x)
    dx[2:, 2] = -3.0
    t = pot.step_bound(x, dx)
    # the gap of 0.11 to the wall closes at t = 0.11 / 3: the bound stops just short of it (0.9
    # of it with the default close fraction), not anywhere short (a too-timid bound costs
    # Newton steps)
    assert 0.8 * 0.11 / 3.0 < t < 0.11 / 3.0
    assert pot.clearance(x + t * dx) > 1.0 - 0.01
    assert not pot.path_is_free(x, x + dx)
    assert pot.path_is_free(x, x + 0.5 * t * dx)
    # a node falling onto the floor moves linearly in height: its bound is exactly the close
    # fraction of its time of impact with the wall, (1.0 - (r - offset)) / 3
    net = Network([[-1, 0, 1.0], [1, 0, 1.0]], [[0, 1]])
    pot = ContactPotential(Contact(radius=0.5, obstacles=(Floor(),), activation_distance=0.01), net)
    dx = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, -3.0]])
    assert pot.step_bound(net.nodes, dx) == pytest.approx(0.9 * 0.51 / 3.0, rel=1e-12)


def test_obstacle_constructors_check_units_and_shapes():
    with pytest.raises(InvalidParameterError, match=r"Sphere\.radius"):
        Sphere((0, 0, 0), -1.0)
    with pytest.raises(InvalidParameterError, match=r"Cylinder\.end"):
        Cylinder((0, 0, 0), (0, 0, 0), 1.0)
    with pytest.raises(InvalidParameterError, match=r"Floor\.normal"):
        Floor(0.0, (0, 0, 0))
    with pytest.raises(InvalidParameterError, match=r"Contact\.radius"):
        Contact(radius=0.0)
    with pytest.raises(InvalidParameterError, match=r"Contact\.obstacles"):
        Contact(radius=0.3, obstacles=("floor",))  # type: ignore[arg-type]
    for bad in (0.0, -1.0, np.inf, np.nan):
        with pytest.raises(InvalidParameterError, match=r"Contact\.stiffness_scale"):
            Contact(radius=0.3, stiffness_scale=bad)
    cyl = Cylinder.along((0, 0, 1), (1, 0, 0), radius=1.75, length=20.0)
    assert cyl.start == (-10.0, 0.0, 1.0) and cyl.moved((0, 0, 1)).end == (10.0, 0.0, 2.0)
    assert Floor(normal=(0, 0, 2)).normal == (0.0, 0.0, 1.0)
    assert Sphere((0, 0, 0), 2.5).moved((1, 0, 0)).centre == (1.0, 0.0, 0.0)


def test_bath_density_is_data_with_a_source():
    from rotomorph.materials.bath import bath_density, bath_fluids

    assert bath_density() == pytest.approx(0.97)
    assert bath_density(temperature=175.0) == pytest.approx(0.97 / (1 + 0.00096 * 150))
    assert "PMX-200" in bath_fluids()["silicone_oil"]["source"]
    with pytest.raises(InvalidParameterError, match="known"):
        bath_density("water")


def test_rod_pressed_on_a_cylinder_obstacle_feels_the_load():
    """The beam of the crossing-rod test pushed onto a fixed Cylinder obstacle instead: the force
    on the obstacle balances the load minus the beam's spring force."""
    model, _, loads, closing, nb = _beam_on_rod(3.0)
    beam = Model(
        Network(model.network.nodes[:nb], model.network.edges[: nb - 1]),
        *(np.asarray(getattr(model, k))[: nb - 1] for k in (
            "bending_stiffness1", "bending_stiffness2", "twist_stiffness", "axial_stiffness"
        )),
    )  # fmt: skip
    rod = Cylinder.along((0.0, 0.0, 0.0), (0.0, 1.0, 0.0), radius=R, length=10.0)
    contact = Contact(radius=R, obstacles=(rod,), activation_distance=2e-3)
    res = solve_static(
        beam, Supports(pinned_nodes=(0, nb - 1), fixed_twist_edges=(0,)), loads, contact=contact
    )
    (force,) = res.contact.obstacle_forces(res.positions)
    assert -force[2] == pytest.approx(2.0 * closing, rel=0.02)


def test_free_filament_rests_on_two_cylinders_under_its_weight():
    """A free filament (no support) across two fixed parallel rods carries its buoyant weight on
    them: spheres and cylinders hold a free body where it touches, so no rigid motion is
    projected out of its steps (a frictionless floor alone leaves three). Lying square across
    the rods is a saddle (turning about the vertical lengthens the span, and the sag lowers the
    weight): the solver leaves it and the filament comes to rest turned, still certified."""
    x = np.linspace(-5.0, 5.0, 21)
    pts = np.stack([x, 0 * x, np.full_like(x, 2.1 * R)], 1)
    EI = E * np.pi * R**4 / 4
    model = Model.chain(
        pts, bending_stiffness1=EI, bending_stiffness2=EI, twist_stiffness=EI / 1.5,
        axial_stiffness=E * np.pi * R**2,
    )  # fmt: skip
    rods = tuple(Cylinder.along((a, 0.0, 0.0), (0.0, 1.0, 0.0), radius=R) for a in (-3.0, 3.0))
    gravity = Gravity(density=1.2, area=np.pi * R**2, fluid_density=0.97)
    res = solve_static(model, loads=Loads(gravity=gravity), contact=Contact(R, rods))
    assert res.stable and res.escapes >= 1
    weight = float((gravity.line_weight(20) * np.diff(x)).sum())
    left, right = res.contact.obstacle_forces(res.positions)
    assert -(left + right)[2] == pytest.approx(weight, rel=1e-6)
    # moments about the centre of weight balance (the sliding position along the rods is
    # nearly neutral, so the split between the rods follows where it came to rest)
    w = np.r_[0.5, np.ones(19), 0.5]
    centre = float(w @ res.positions[:, 0] / w.sum())
    moment = left[2] * (-3.0 - centre) + right[2] * (3.0 - centre)
    assert abs(moment) < 1e-3 * weight * 3.0


def test_path_check_reusing_the_step_candidates_decides_as_a_fresh_one(rng):
    """``path_is_free`` after a ``step_bound`` from the same start reuses that step's swept
    candidates when the path ends near the swept boxes; its verdict equals a fresh broad phase
    for end points on, near and off the step (crossing rods, a floor, a sphere)."""
    net = Network(
        [[-2, 0, 1.2], [0, 0, 1.2], [2, 0, 1.2], [0, -2, 2.3], [0, 0, 2.3], [0, 2, 2.3]],
        [[0, 1], [1, 2], [3, 4], [4, 5]],
    )
    contact = Contact(0.5, (Floor(0.0), Sphere((3.0, 0.0, 1.2), 0.4)), activation_distance=0.05)
    reused = ContactPotential(contact, net)
    builds = [0]
    build = reused._build_candidates

    def counted(*args, **kwargs):  # type: ignore[no-untyped-def]
        builds[0] += 1
        return build(*args, **kwargs)

    reused._build_candidates = counted  # type: ignore[method-assign]
    verdicts, checks = [], 0
    for _ in range(60):
        x = net.nodes + 0.02 * rng.standard_normal(net.nodes.shape)
        dx = rng.standard_normal(x.shape) * rng.choice([0.05, 0.3, 1.0])
        reused.step_bound(x, dx)
        for beta, wobble in ((1.0, 0.0), (0.5, 0.003), (1.0, 0.006), (0.3, 0.2)):
            x1 = x + beta * dx + wobble * rng.standard_normal(x.shape)
            fresh = ContactPotential(contact, net).path_is_free(x, x1)
            assert reused.path_is_free(x, x1) == fresh
            verdicts.append(fresh)
            checks += 1
    assert any(verdicts) and not all(verdicts)  # both verdicts were exercised
    assert builds[0] < 60 + checks / 2  # most checks reused the step's candidates


def test_excluded_pairs_are_remembered_per_network_and_settings():
    """The solves of a ramp bind the same network once per step: its excluded pairs are
    computed once per settings and equal a fresh computation."""
    from rotomorph.contact.exclusion import excluded_pairs

    model, _ = _filament(1.2 * R, n=41)
    net = model.network
    a = ContactPotential(Contact(R), net)
    b = ContactPotential(Contact(R), net)
    assert a.excluded is b.excluded
    fresh = excluded_pairs(net.nodes, np.asarray(net.edges, np.int64), a.radius, a.dhat)
    assert np.array_equal(a.excluded, fresh) and len(fresh)
    wider = ContactPotential(Contact(R, reach=4.0 * R), net)
    assert wider.excluded is not a.excluded and len(wider.excluded) > len(a.excluded)


def test_stiffness_scale_multiplies_the_default_stiffness_only():
    net = Network(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1], [1, 2]]))
    base = ContactPotential(Contact(radius=0.1), net, force_scale=2.0).kappa
    soft = ContactPotential(Contact(radius=0.1, stiffness_scale=0.01), net, force_scale=2.0)
    assert soft.kappa == pytest.approx(0.01 * base, rel=1e-15)
    given = Contact(radius=0.1, stiffness=3.0, stiffness_scale=0.01)
    assert ContactPotential(given, net).kappa == 3.0


def test_offset_is_checked_and_defaults_to_the_activation_distance():
    net = Network(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1], [1, 2]]))
    pot = ContactPotential(Contact(radius=0.1), net)
    assert pot.dhat == pytest.approx(0.01 * 0.2) and pot.offset == pot.dhat
    assert ContactPotential(Contact(radius=0.1, offset=0.0), net).offset == 0.0
    for bad in (-1e-3, 0.1, np.nan):
        with pytest.raises(InvalidParameterError, match=r"Contact\.offset"):
            Contact(radius=0.1, offset=bad)
    # an activation distance beyond the radius would put the default offset's wall below 0
    with pytest.raises(InvalidParameterError, match=r"Contact\.offset"):
        ContactPotential(Contact(radius=0.1, activation_distance=0.2), net)


def test_pressed_contacts_settle_within_half_a_percent_of_touching():
    model, supports, loads, _, _ = _beam_on_rod(3.0)
    res = solve_static(model, supports, loads, contact=Contact(radius=R))
    ratios = res.contact.contact_ratios(res.positions)
    assert len(ratios) == res.contact.active_contacts(res.positions) > 0
    assert np.all((ratios > 1 - 5e-3) & (ratios < 1.0))
    assert ratios.min() == pytest.approx(res.contact.clearance(res.positions), rel=1e-12)
