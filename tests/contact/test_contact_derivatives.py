"""Contact energy: gradients and Hessians against central finite differences."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from rotomorph.contact import Contact, ContactPotential, Cylinder, Floor, Sphere
from rotomorph.contact.distance import closest_parameters, segment_distance2
from rotomorph.contact.friction import friction_energy
from rotomorph.design.network import Network


def _d2(x, need=False):
    g, h = np.empty(12), np.empty((12, 12))
    d = segment_distance2(x[0:3], x[3:6], x[6:9], x[9:12], need, g, h)
    return d, g, h


def _same_type(x, eps):
    """True when the closest-point type (which parameters are interior) is the same at +-eps."""

    def kind(y):
        s, t = closest_parameters(y[0:3], y[3:6], y[6:9], y[9:12])
        return (0 < s < 1, 0 < t < 1)

    k = kind(x)
    return all(kind(x + eps * e) == k and kind(x - eps * e) == k for e in np.eye(len(x)))


@pytest.mark.parametrize("kind", ["crossing", "parallel", "point"])
def test_squared_distance_matches_finite_differences(kind):
    rng = np.random.default_rng(7)
    eps, checked = 1e-6, 0
    for _ in range(40):
        x = rng.standard_normal(12)
        if kind == "parallel":  # nearly parallel, overlapping
            x[9:12] = x[6:9] + (x[3:6] - x[0:3]) * (0.5 + rng.random())
            x[9:12] += 1e-2 * rng.standard_normal(3)
        if kind == "point":
            x[9:12] = x[6:9]
        if kind != "point" and not _same_type(x, eps):
            continue
        _, g, h = _d2(x, True)
        cols = 6 if kind == "point" else 12  # a point's two copies are one obstacle DOF
        gf = np.array([(_d2(x + eps * e)[0] - _d2(x - eps * e)[0]) / (2 * eps) for e in np.eye(12)])
        hf = np.array([(_d2(x + eps * e)[1] - _d2(x - eps * e)[1]) / (2 * eps) for e in np.eye(12)])
        assert np.allclose(g[:cols], gf[:cols], rtol=1e-6, atol=1e-7)
        assert np.allclose(h[:cols, :cols], hf[:cols, :cols], rtol=1e-5, atol=1e-6)
        checked += 1
    assert checked >= 20


def _gap2(u, p0, a, q0, b):
    """|p(s) - q(t)|^2 at u = (s, t)."""
    return float(np.sum((p0 + u[0] * a - q0 - u[1] * b) ** 2))


@pytest.mark.parametrize("kind", ["crossing", "parallel", "point"])
def test_squared_distance_is_the_minimum_over_both_segments(kind):
    """The value itself (the test above checks only its derivatives): the minimum of
    |p(s) - q(t)|^2 over the unit square, found independently by a bounded quasi-Newton search
    from the best point of a grid. Skipping one of the square's edges passed tests/contact."""
    from scipy.optimize import minimize

    rng = np.random.default_rng(11)
    for _ in range(30):
        x = rng.standard_normal(12)
        if kind == "parallel":
            x[9:12] = x[6:9] + (x[3:6] - x[0:3]) * (0.5 + rng.random())
        if kind == "point":
            x[9:12] = x[6:9]
        p0, a, q0, b = x[0:3], x[3:6] - x[0:3], x[6:9], x[9:12] - x[6:9]
        grid = np.linspace(0.0, 1.0, 21)
        start = min(((s, t) for s in grid for t in grid), key=lambda u: _gap2(u, p0, a, q0, b))
        ref = minimize(_gap2, start, (p0, a, q0, b), bounds=[(0, 1), (0, 1)], method="L-BFGS-B",
                       options={"ftol": 1e-15, "gtol": 1e-12}).fun  # fmt: skip
        assert _d2(x)[0] == pytest.approx(ref, rel=1e-7, abs=1e-12)


def _two_segments(kind, rng, outside=False):
    """Two 3-node filaments pressed 0.2-0.4 % into contact (radius 0.5: contact distance 1.0,
    inside the default barrier's zone) or, with ``outside``, as far apart of it (inside the
    zone of a barrier with ``offset=0``)."""
    sign = 1.0 if outside else -1.0
    if kind == "crossing":
        a = np.array([[-1.0, 0.2, 0], [0.1, 0.0, 0], [1.1, -0.1, 0]])
        b = np.array([[0.2, -1.0, 0.003], [0.0, 0.1, 0.004], [-0.1, 1.0, 0.002]])
        b[:, 2] = 1.0 + sign * b[:, 2]
    else:  # parallel, offset along the axis
        a = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
        b = np.array([[0.4, 0.004, 0.0], [1.4, 0.003, 0.001], [2.4, 0.002, 0.0]])
        b[:, 1] = 1.0 + sign * b[:, 1]
    pts = np.vstack([a, b]) + 2e-4 * rng.standard_normal((6, 3))
    printed = pts + np.array([[0, 0, 0]] * 3 + [[0, 0, 5.0]] * 3)  # printed apart: not fused
    return Network(printed, [[0, 1], [1, 2], [3, 4], [4, 5]]), pts


def _check_potential(pot, x, eps=1e-7):
    e, g, trip = pot.evaluate(x, True, 1)
    assert np.isfinite(e) and e > 0
    n3 = x.size
    H = np.zeros((n3, n3))
    np.add.at(H, (trip[0], trip[1]), trip[2])
    gf = np.zeros(n3)
    hf = np.zeros((n3, n3))
    for k in range(n3):
        dx = np.zeros(n3)
        dx[k] = eps
        ep, gp, _ = pot.evaluate(x + dx.reshape(x.shape), True, 0)
        em, gm, _ = pot.evaluate(x - dx.reshape(x.shape), True, 0)
        gf[k] = (ep - em) / (2 * eps)
        hf[:, k] = (gp - gm).ravel() / (2 * eps)
    scale = np.abs(g).max()
    assert np.abs(g.ravel() - gf).max() <= 1e-5 * scale
    assert np.abs(H - hf).max() <= 1e-4 * np.abs(H).max()
    assert np.allclose(H, H.T, atol=1e-12 * np.abs(H).max())


@pytest.mark.parametrize("offset", [None, 0.0], ids=["default", "outside"])
@pytest.mark.parametrize("kind", ["crossing", "parallel"])
def test_self_contact_barrier_matches_finite_differences(kind, offset, rng):
    net, pts = _two_segments(kind, rng, outside=offset == 0.0)
    contact = Contact(radius=0.5, activation_distance=0.01, stiffness=1.0, offset=offset)
    _check_potential(ContactPotential(contact, net), pts)


@pytest.mark.parametrize(
    "obstacle",
    [  # the filament pressed 0.5 % of a radius (0.6 % of r + R) into each, in the zone
        Floor(height=-0.4975),
        Sphere(centre=(0.3, 0.0, -2.494), radius=2.0),
        Cylinder.along((0.4, 0.0, -0.994), (0.1, 1.0, 0.0), radius=0.5, length=10.0),
    ],
    ids=["plane", "sphere", "cylinder"],
)
def test_obstacle_barrier_matches_finite_differences(obstacle, rng):
    pts = np.array([[-1.0, 0.0, 0.0], [0.2, 0.1, 0.001], [1.2, -0.1, 0.002]])
    pts += 1e-4 * rng.standard_normal(pts.shape)
    net = Network(pts, [[0, 1], [1, 2]])
    contact = Contact(radius=0.5, obstacles=(obstacle,), activation_distance=0.02, stiffness=1.0)
    _check_potential(ContactPotential(contact, net), pts)


def test_psd_mode_is_positive_semidefinite(rng):
    net, pts = _two_segments("crossing", rng)
    pot = ContactPotential(Contact(radius=0.5, activation_distance=0.01, stiffness=1.0), net)
    _, _, trip = pot.evaluate(pts, False, 2)
    H = np.zeros((18, 18))
    np.add.at(H, (trip[0], trip[1]), trip[2])
    assert np.linalg.eigvalsh(H).min() >= -1e-9 * np.abs(H).max()


@pytest.mark.parametrize("slip", [1e-2, 1e-4], ids=["sticking", "sliding"])
def test_lagged_friction_matches_finite_differences(slip, rng):
    """Barrier plus lagged friction (pair and floor contacts), lagged at one configuration and
    evaluated after a tangential slip of ~1e-3 mm: inside (sticking) or beyond (sliding) the
    smoothing slip."""
    net, pts = _two_segments("crossing", rng)
    contact = Contact(
        radius=0.5,
        obstacles=(Floor(height=-0.4955),),
        activation_distance=0.01,
        stiffness=1.0,
        friction=0.5,
        slip=slip,
    )
    pot = ContactPotential(contact, net)
    pot.set_lag(pts)
    assert pot._lag is not None and pot._lag.count >= 4  # pair contacts and floor nodes
    moved = pts + 1e-3 * rng.standard_normal(pts.shape) * [1.0, 1.0, 0.05]
    _check_potential(pot, moved, eps=1e-8)


def test_friction_force_is_coulomb_when_sliding_and_smoothed_when_sticking(rng):
    """A rigid slide along x: pair contacts do not slip (both sides move alike), each floor
    node slips by the slide. Far beyond the smoothing slip a floor node's friction force is the
    Coulomb bound mu * lambda along the slide, exactly; within it, mu * lambda * f1(y) with the
    hand-evaluated f1(eps / 2) = 3/4 (an upper bound alone would pass with friction switched
    off or its coefficient halved)."""
    net, pts = _two_segments("crossing", rng)
    contact = Contact(radius=0.5, obstacles=(Floor(height=-0.4955),), stiffness=1.0)
    pot = ContactPotential(replace(contact, friction=0.3, slip=1e-4), net)
    lag = pot.lag(pts)
    assert lag.normal_force.min() > 0
    on_floor = np.all(lag.weights[:, 1:] == 0, axis=1)
    assert on_floor.sum() == 3 and (~on_floor).sum() >= 4  # floor nodes 0-2 and pair contacts
    # the lagged normal forces are the barrier's: together, what the floor carries
    (on_the_floor,) = pot.obstacle_forces(pts)
    assert lag.normal_force[on_floor].sum() == pytest.approx(-on_the_floor[2], rel=1e-12)
    bound = np.zeros((6, 3))
    bound[lag.nodes[on_floor, 0], 0] = 0.3 * lag.normal_force[on_floor]
    for slide, f1 in ((0.05, 1.0), (0.5e-4, 0.75)):
        moved = pot._extended(pts + np.array([slide, 0.0, 0.0]))
        _, g, _ = friction_energy(lag, moved, True, False)
        np.testing.assert_allclose(g, f1 * bound, rtol=1e-9, atol=1e-12)
