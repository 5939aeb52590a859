"""Axial section mechanics: general quadrature vs closed forms (benchmarks X1, X4)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.closed_form import (
    curvature_factor,
    h0,
    h1,
    janus_axial_stiffness,
    janus_bending_stiffness,
    janus_centroid,
    janus_curvature,
    janus_curvature_helical,
)
from rotomorph.materials.janus import filament_section
from rotomorph.materials.mesh import disk_mesh, interface_offset, rectangle_mesh
from rotomorph.materials.section import axial_section, phase_constant

R = 0.3
QUAD_RTOL = 2e-3  # polygonal disk with 128 boundary vertices


def test_x1_curvature_factor_at_m1() -> None:
    assert curvature_factor(1.0) == pytest.approx(8.0 / (3.0 * math.pi), rel=1e-12)
    mesh = disk_mesh(R, 0.5, 128)
    sec = axial_section(mesh, 1.0)
    de = 0.1
    kappa = sec.natural_curvature(phase_constant(0.0, de))  # active contracts relative
    assert kappa[0] * R / de == pytest.approx(8.0 / (3.0 * math.pi), rel=1e-3)
    assert abs(kappa[1]) < 1e-12


def test_x4_timoshenko_bilayer_through_general_quadrature() -> None:
    # t1 = 1 (E1 = 3, strain 0), t2 = 2 (E2 = 1, strain 0.01); Timoshenko 1925: 0.00497696
    mesh = rectangle_mesh(1.0, (1.0, 2.0), active_layer=0, n=4)
    sec = axial_section(mesh, phase_constant(3.0, 1.0))
    kappa = sec.natural_curvature(phase_constant(0.0, 0.01))
    # the expanding layer 2 lies at larger x1, so the strip bends toward -x1 (toward layer 1)
    assert kappa[0] == pytest.approx(-0.00497696, rel=1e-5)
    mt, n, h = 0.5, 3.0, 3.0
    exact = (
        6 * 0.01 * (1 + mt) ** 2 / (h * (3 * (1 + mt) ** 2 + (1 + mt * n) * (mt**2 + 1 / (mt * n))))
    )
    assert -kappa[0] == pytest.approx(exact, rel=1e-12)


# reference table (computed independently): m, f(m), B_n/B_eta, xi_c/R
TABLE = [
    (1, 0.8488, 1.000, 0.0),
    (2, 0.8202, 0.920, 0.1415),
    (3, 0.7765, 0.820, 0.2122),
    (5, 0.6937, 0.680, 0.2829),
    (10, 0.5420, 0.518, 0.3472),
    (20, 0.3754, 0.410, 0.3840),
    (52.05, 0.1887, 0.333, 0.4084),
]


@pytest.mark.parametrize(("m", "f", "ratio", "xi"), TABLE)
def test_janus_table_closed_form_and_quadrature(
    m: float, f: float, ratio: float, xi: float
) -> None:
    ea, ep = m * 0.57, 0.57
    assert curvature_factor(m) == pytest.approx(f, abs=1e-4)
    b_n, b_eta = janus_bending_stiffness(ea, ep, R)
    assert b_n / b_eta == pytest.approx(ratio, abs=1e-3)
    assert janus_centroid(ea, ep, R) / R == pytest.approx(xi, abs=1e-4)
    sec = filament_section(R, ea, ep, resolution=128)
    assert sec.bending_stiffness1 == pytest.approx(b_n, rel=QUAD_RTOL)
    assert sec.bending_stiffness2 == pytest.approx(b_eta, rel=QUAD_RTOL)
    assert sec.axial_stiffness == pytest.approx(janus_axial_stiffness(ea, ep, R), rel=QUAD_RTOL)
    assert sec.axial.centroid[0] == pytest.approx(
        janus_centroid(ea, ep, R), rel=QUAD_RTOL, abs=1e-9
    )
    assert abs(sec.axial.bending_matrix[0, 1]) < 1e-9 * b_eta
    _, kappa, _ = sec.natural_strains(0.0, -0.2, 0.1, 0.03)
    assert kappa[0, 0] == pytest.approx(janus_curvature(0.23, m, R), rel=QUAD_RTOL)


def test_paper_room_temperature_stiffness() -> None:
    # reference values: B_n = 0.0320, B_eta = 0.0962 N mm^2, A_E = 4.28 N at 25 C
    b_n, b_eta = janus_bending_stiffness(29.67, 0.57, R)
    assert b_n == pytest.approx(0.0320, abs=1e-4)
    assert b_eta == pytest.approx(0.0962, abs=1e-4)
    assert janus_axial_stiffness(29.67, 0.57, R) == pytest.approx(4.28, abs=0.01)


def test_curvature_factor_symmetry_and_maximum() -> None:
    m = np.array([0.01, 0.2, 0.5, 2.0, 7.0, 52.0, 300.0])
    np.testing.assert_allclose(curvature_factor(m), curvature_factor(1.0 / m), rtol=1e-12)
    grid = np.exp(np.linspace(-3, 3, 601))
    assert grid[np.argmax(curvature_factor(grid))] == pytest.approx(1.0, rel=0.01)


def test_scaling_with_radius() -> None:
    a = filament_section(R, 3.0, 1.0, resolution=64)
    b = filament_section(2 * R, 3.0, 1.0, resolution=64)
    assert b.bending_stiffness1 / a.bending_stiffness1 == pytest.approx(16.0, rel=1e-10)
    assert b.twist_stiffness / a.twist_stiffness == pytest.approx(16.0, rel=1e-10)
    assert b.axial_stiffness / a.axial_stiffness == pytest.approx(4.0, rel=1e-10)
    ka = a.natural_strains(0.5, -0.2, 0.1, 0.03)[1][0, 0]
    kb = b.natural_strains(0.5, -0.2, 0.1, 0.03)[1][0, 0]
    assert kb / ka == pytest.approx(0.5, rel=1e-10)


@pytest.mark.parametrize("m", [1.0, 3.0, 52.05])
def test_helical_director_curvature_and_strain(m: float) -> None:
    w = np.array([0.0, 0.06, 0.25, 1.0, 2.0])
    ep, et, eq = -0.213, 0.1065, 0.0296
    sec = filament_section(R, m, 1.0, resolution=128)
    eps_c, kappa, _ = sec.natural_strains(w, ep, et, eq)
    closed = janus_curvature_helical(w, ep, et, eq, m, 1.0, R)
    np.testing.assert_allclose(kappa[:, 0], closed, rtol=QUAD_RTOL, atol=2e-4)
    np.testing.assert_allclose(
        eps_c, (m * (et + (ep - et) * h0(w**2)) + eq) / (m + 1), rtol=QUAD_RTOL, atol=1e-5
    )
    # helical profile reverses K_J at high rotation for the stiff active phase
    if m > 50:
        assert kappa[0, 0] > 0 > kappa[-1, 0]


def test_h0_h1_series_and_limits() -> None:
    a = np.array([0.0, 1e-4, 2e-3, 1.0, 4.0])
    assert h0(0.0) == 1.0 and h1(0.0) == 1.0
    assert h0(4.0) == pytest.approx(math.log(5) / 4)
    assert h1(1.0) == pytest.approx(3 * (1 - math.pi / 4))
    # continuity across the series switch
    assert h0(0.999e-3) == pytest.approx(h0(1.001e-3), rel=1e-5)
    assert h1(0.999e-3) == pytest.approx(h1(1.001e-3), rel=1e-5)
    assert np.all(np.diff(h0(a)) < 0) and np.all(np.diff(h1(a)) < 0)


def test_general_active_fraction_segment() -> None:
    f = 0.3
    d = interface_offset(R, f)
    mesh = disk_mesh(R, f, 128)
    area = mesh.areas
    assert area[mesh.active].sum() / area.sum() == pytest.approx(f, rel=2e-3)
    # void-like passive phase: centroid of the circular segment 2 (R^2 - d^2)^1.5 / (3 A)
    sec = axial_section(mesh, phase_constant(1.0, 1e-9))
    exact = 2 * (R * R - d * d) ** 1.5 / (3 * f * math.pi * R * R)
    assert sec.centroid[0] == pytest.approx(exact, rel=QUAD_RTOL)
    # a uniform eigenstrain gives pure stretch, no curvature
    sec = axial_section(mesh, phase_constant(7.0, 1.0))
    assert sec.natural_strain(0.05) == pytest.approx(0.05, rel=1e-12)
    np.testing.assert_allclose(sec.natural_curvature(0.05), 0.0, atol=1e-12)
    # any eigenstrain field linear in x is reproduced exactly: eps = a + b.x -> kappa = -b
    field = lambda xy, act: 0.01 + 0.2 * xy[:, 0] - 0.1 * xy[:, 1]  # noqa: E731
    np.testing.assert_allclose(sec.natural_curvature(field), [-0.2, 0.1], atol=1e-12)


def test_mesh_is_conforming() -> None:
    mesh = disk_mesh(R, 0.5, 64)
    edges = np.sort(mesh.triangles[:, [0, 1, 1, 2, 2, 0]].reshape(-1, 2), axis=1)
    _, counts = np.unique(edges, axis=0, return_counts=True)
    assert set(counts.tolist()) <= {1, 2}
    assert int(np.sum(counts == 1)) == 64  # only the polygon boundary edges are unshared
    v, e, t = len(mesh.points), len(counts), len(mesh.triangles)
    assert v - e + t == 1  # a disk


def test_bad_inputs() -> None:
    with pytest.raises(InvalidParameterError, match="active_fraction"):
        disk_mesh(R, 0.0)
    with pytest.raises(InvalidParameterError, match="radius"):
        interface_offset(-1.0, 0.5)
    with pytest.raises(InvalidParameterError, match="modulus"):
        axial_section(disk_mesh(R, 0.5, 32), phase_constant(1.0, -1.0))
    with pytest.raises(InvalidParameterError, match="e_active"):
        filament_section(R, 0.0, 1.0)


def test_pure_sections_are_special_cases() -> None:
    e = 2.0
    lce = filament_section(R, e, 1.0, active_fraction=1.0, resolution=128)
    for b in (lce.bending_stiffness1, lce.bending_stiffness2):
        assert b == pytest.approx(e * math.pi * R**4 / 4, rel=QUAD_RTOL)
    assert lce.twist_stiffness == pytest.approx(e / 3 * math.pi * R**4 / 2, rel=QUAD_RTOL)
    assert lce.axial_stiffness == pytest.approx(e * math.pi * R**2, rel=QUAD_RTOL)
    # pure passive = homogeneous disk with an isotropic eigenstrain: pure stretch, nothing else
    eps_c, kappa, tau = lce.natural_strains(0.7, 0.03, 0.03, 0.0)
    assert eps_c[0] == pytest.approx(0.03, rel=1e-12)
    np.testing.assert_allclose(kappa, 0.0, atol=1e-12)
    np.testing.assert_allclose(tau, 0.0, atol=1e-12)
    # Janus section with equal strains in both phases: same result
    jan = filament_section(R, 3.0, 1.0, resolution=64)
    eps_c, kappa, tau = jan.natural_strains(0.0, 0.03, 0.03, 0.03)
    assert eps_c[0] == pytest.approx(0.03, rel=1e-12)
    np.testing.assert_allclose(kappa, 0.0, atol=1e-12)
