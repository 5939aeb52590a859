"""Quadratic surface fits on exact surfaces, and discrete polyline curvature colouring."""

from __future__ import annotations

import numpy as np
import pytest
from _analysis_builders import helix_points, random_rotation, sinusoidal_lattice

from rotomorph.analysis.curvature import (
    discrete_curvature,
    discrete_torsion,
    fit_quadratic_surface,
    network_relative_curvature_change,
    relative_curvature_change,
)
from rotomorph.errors import InvalidParameterError

R = 50.0


def grid(half_width: float = 5.0, count: int = 5):
    g = np.linspace(-half_width, half_width, count)
    x, y = np.meshgrid(g, g)
    return x.ravel(), y.ravel()


def sphere_cap(sign: float = 1.0):
    x, y = grid()
    return np.stack([x, y, sign * (R - np.sqrt(R * R - x * x - y * y))], axis=1)


def test_bowl_sphere():
    fit = fit_quadratic_surface(sphere_cap(+1.0))
    assert fit.k1 == pytest.approx(1 / R, rel=0.01)
    assert fit.k2 == pytest.approx(1 / R, rel=0.01)
    assert fit.gaussian_sign == 1
    assert fit.characteristic_curvature == pytest.approx(1 / R, rel=0.01)
    assert fit.small_slope_gaussian == pytest.approx(1 / R**2, rel=0.02)


def test_dome_is_negative_wrt_upward_normal_but_same_gaussian():
    fit = fit_quadratic_surface(sphere_cap(-1.0))
    assert fit.k1 == pytest.approx(-1 / R, rel=0.01)
    assert fit.k2 == pytest.approx(-1 / R, rel=0.01)
    assert fit.gaussian_sign == 1
    assert fit.frame[2, 2] > 0


def test_saddle_exact():
    x, y = grid()
    fit = fit_quadratic_surface(np.stack([x, y, (x * x - y * y) / (2 * R)], 1))
    assert fit.k1 == pytest.approx(1 / R, rel=1e-10)
    assert fit.k2 == pytest.approx(-1 / R, rel=1e-10)
    assert fit.gaussian_sign == -1
    assert fit.characteristic_curvature == pytest.approx(1 / R, rel=1e-10)


def test_cylinder_and_plane_are_flat():
    x, y = grid()
    cyl = fit_quadratic_surface(np.stack([x, y, R - np.sqrt(R * R - x * x)], 1))
    assert cyl.k1 == pytest.approx(1 / R, rel=0.01)
    assert abs(cyl.k2) < 1e-12
    assert cyl.gaussian_sign == 0
    plane = fit_quadratic_surface(np.stack([x, y, 0.3 * x - 0.2 * y + 1.0], 1))
    assert plane.gaussian_sign == 0
    assert abs(plane.k1) < 1e-12 and abs(plane.k2) < 1e-12


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_rigid_motion_invariance(seed):
    rot = random_rotation(seed)
    base = fit_quadratic_surface(sphere_cap())
    x, y = grid()
    saddle = np.stack([x, y, (x * x - 0.5 * y * y) / R], 1)
    for pts in (sphere_cap(), saddle):
        ref = fit_quadratic_surface(pts)
        moved = fit_quadratic_surface(pts @ rot.T + [10.0, -3.0, 7.0])
        assert moved.gaussian_curvature == pytest.approx(ref.gaussian_curvature, rel=1e-8)
        assert sorted(np.abs([moved.k1, moved.k2])) == pytest.approx(
            sorted(np.abs([ref.k1, ref.k2])), rel=1e-8
        )
    assert base.gaussian_sign == 1


def test_off_centre_patch_uses_full_shape_operator():
    # a sphere patch seen off-centre: PCA tilts the frame; K = (4ac - b^2)/(1 + d^2 + e^2)^2
    x, y = grid(5.0, 5)
    cx = 30.0
    z = R - np.sqrt(R * R - (x + cx) ** 2 - y * y)
    fit = fit_quadratic_surface(np.stack([x + cx, y, z], 1))
    _, _, _, d, e, _ = fit.coefficients
    assert fit.gaussian_curvature == pytest.approx(
        fit.small_slope_gaussian / (1 + d * d + e * e) ** 2, rel=1e-12
    )
    assert fit.gaussian_curvature == pytest.approx(fit.k1 * fit.k2, rel=1e-10)
    assert fit.gaussian_curvature == pytest.approx(1 / R**2, rel=0.02)
    assert fit.gaussian_sign == 1


def test_sign_robust_to_noise():
    rng = np.random.default_rng(0)
    x, y = grid(10.0, 5)
    for z, sign in (((x * x + y * y) / 400, 1), ((x * x - y * y) / 400, -1)):
        for _ in range(5):
            pts = np.stack([x, y, z + rng.normal(scale=0.01, size=z.shape)], 1)
            assert fit_quadratic_surface(pts).gaussian_sign == sign


def test_lattice_branch_nodes_of_a_domed_lattice():
    pos, _ = sinusoidal_lattice()
    branch = pos[:25].copy()
    c = branch[:, :2] - 20.0
    branch[:, 2] = -(c**2).sum(axis=1) / (2 * 100.0)
    fit = fit_quadratic_surface(branch)
    assert fit.gaussian_sign == 1
    assert fit.characteristic_curvature == pytest.approx(1 / 100.0, rel=1e-10)


def test_degenerate_inputs():
    with pytest.raises(InvalidParameterError, match="at least 6 points"):
        fit_quadratic_surface(sphere_cap()[:5])
    with pytest.raises(InvalidParameterError, match="collinear"):
        fit_quadratic_surface(np.linspace([0, 0, 0], [1, 2, 0], 8))
    with pytest.raises(InvalidParameterError, match="coincide"):
        fit_quadratic_surface(np.ones((7, 3)))
    with pytest.raises(InvalidParameterError, match="finite"):
        fit_quadratic_surface(np.full((7, 3), np.nan))


def test_discrete_curvature_and_torsion_of_helix():
    r, c = 2.0, 0.5
    pts = helix_points(r, c, 2.0, 400)
    np.testing.assert_allclose(discrete_curvature(pts), r / (r * r + c * c), rtol=1e-3)
    np.testing.assert_allclose(discrete_torsion(pts), c / (r * r + c * c), rtol=1e-3)
    left = helix_points(r, c, 2.0, 400, sign=-1)
    np.testing.assert_allclose(discrete_torsion(left), -c / (r * r + c * c), rtol=1e-3)
    line = np.linspace([0, 0, 0], [3, 0, 0], 6)
    assert np.all(discrete_curvature(line) == 0.0)
    assert np.all(np.isnan(discrete_torsion(line)))


def test_relative_curvature_change_of_circles():
    theta = np.linspace(0, np.pi, 40)
    arc = np.stack([np.cos(theta), np.sin(theta), 0 * theta], 1)
    change = relative_curvature_change(arc * 2.5, arc * 5.0)
    assert np.isnan(change[0]) and np.isnan(change[-1])
    np.testing.assert_allclose(change[1:-1], 1.0, rtol=1e-12)
    straight = np.linspace([0, 0, 0], [1, 0, 0], 5)
    assert np.all(np.isnan(relative_curvature_change(straight, straight)))


def test_network_relative_curvature_change():
    pos, chains = sinusoidal_lattice(n=3)
    values = network_relative_curvature_change(pos, pos, chains)
    assert values.shape == (len(pos),)
    assert np.all(np.isnan(values[:9]))  # branch nodes: ends of every chain
    finite = values[np.isfinite(values)]
    assert len(finite) > 0.9 * (len(pos) - 9)
    np.testing.assert_allclose(finite, 0.0, atol=1e-12)
    doubled = network_relative_curvature_change(pos * 2.0, pos, chains)
    np.testing.assert_array_equal(np.isfinite(doubled), np.isfinite(values))
    np.testing.assert_allclose(doubled[np.isfinite(doubled)], -0.5, rtol=1e-12)
