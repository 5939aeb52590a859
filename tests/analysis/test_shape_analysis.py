"""Lengths, end-to-end ratios, helix fits and morphology labels on exact curves."""

from __future__ import annotations

import numpy as np
import pytest
from _analysis_builders import helix_points, random_rotation

from rotomorph.analysis.shape import (
    Morphology,
    arc_length,
    classify_morphology,
    edge_end_to_end_ratios,
    end_to_end_length,
    end_to_end_ratio,
    fit_helix,
    mean_edge_strain,
    polyline_morphology,
    turn_count,
)
from rotomorph.errors import InvalidParameterError
from rotomorph.geometry import rotate_about_tangent, space_parallel_directors


def test_lengths_of_a_square_path():
    pts = np.array([[0, 0, 0], [3, 0, 0], [3, 4, 0], [0, 4, 0]], dtype=float)
    assert arc_length(pts) == pytest.approx(10.0)
    assert end_to_end_length(pts) == pytest.approx(4.0)
    assert end_to_end_ratio(pts, pts * 2.0) == pytest.approx(0.5)


def test_empty_and_single_point_lengths_are_zero():
    assert arc_length(np.zeros((0, 3))) == 0.0
    assert arc_length([[1.0, 2.0, 3.0]]) == 0.0
    assert end_to_end_length(np.zeros((0, 3))) == 0.0


def test_ratio_with_closed_reference_raises():
    loop = np.array([[0, 0, 0], [1, 0, 0], [0, 0, 0]], dtype=float)
    with pytest.raises(InvalidParameterError, match="reference"):
        end_to_end_ratio(loop, loop)


def test_bad_shape_names_the_field():
    with pytest.raises(InvalidParameterError, match=r"points.*\(N, 3\)"):
        arc_length(np.zeros((4, 2)))


def test_circle_arc_length_converges():
    theta = np.linspace(0, 2 * np.pi, 2001)
    circle = np.stack([np.cos(theta), np.sin(theta), 0 * theta], 1) * 5.0
    assert arc_length(circle) == pytest.approx(10 * np.pi, rel=1e-6)


def test_edge_ratios_of_scaled_lattice(lattice):
    pos, chains = lattice
    ratios = edge_end_to_end_ratios(pos * 1.25, pos, chains)
    assert ratios.shape == (40,)
    np.testing.assert_allclose(ratios, 1.25, rtol=1e-14)
    assert mean_edge_strain(pos * 0.8, pos, chains) == pytest.approx(-0.2)
    assert mean_edge_strain(pos, pos, []) == 0.0


def test_edge_ratio_of_one_stretched_edge(lattice):
    pos, chains = lattice
    moved = pos.copy()
    moved[chains[0][-1]] += (moved[chains[0][-1]] - moved[chains[0][0]]) * 0.5
    ratios = edge_end_to_end_ratios(moved, pos, chains)
    assert ratios[0] == pytest.approx(1.5)


@pytest.mark.parametrize(
    ("radius", "rise", "turns", "sign"),
    [
        (2.0, 0.5, 3.0, 1),
        (2.0, 0.5, 3.0, -1),
        (1.0, 3.0, 2.0, 1),
        (0.2, 2.0, 1.5, -1),
        (1.0, 0.01, 4.0, 1),
        (2.0, 0.5, 0.6, 1),
    ],
)
def test_fit_exact_helix_in_any_pose(radius, rise, turns, sign):
    rot = random_rotation(int(radius * 10 + turns))
    pts = helix_points(radius, rise, turns, 150, sign) @ rot.T + [3.0, -4.0, 5.0]
    fit = fit_helix(pts)
    assert fit.radius == pytest.approx(radius, rel=1e-8)
    assert fit.pitch == pytest.approx(2 * np.pi * rise, rel=1e-8)
    assert fit.handedness == sign
    assert fit.turns == pytest.approx(turns, rel=1e-8)
    assert fit.rms_residual < 1e-9
    np.testing.assert_allclose(abs(fit.axis @ rot[:, 2]), 1.0, atol=1e-9)
    assert fit.curvature == pytest.approx(radius / (radius**2 + rise**2), rel=1e-8)
    assert fit.torsion == pytest.approx(sign * rise / (radius**2 + rise**2), rel=1e-8)
    assert turn_count(pts) == pytest.approx(turns, rel=1e-8)


def test_fit_planar_circle_has_zero_pitch():
    fit = fit_helix(helix_points(5.0, 0.0, 1.25, 100))
    assert fit.radius == pytest.approx(5.0)
    assert fit.pitch == 0.0
    assert fit.handedness == 0


def test_fit_noisy_nonuniform_helix():
    rng = np.random.default_rng(3)
    theta = np.sort(rng.uniform(0, 6 * np.pi, 300))
    pts = np.stack([2 * np.cos(theta), 2 * np.sin(theta), 0.7 * theta], 1)
    pts += rng.normal(scale=0.01, size=pts.shape)
    fit = fit_helix(pts)
    assert fit.radius == pytest.approx(2.0, rel=5e-3)
    assert fit.pitch == pytest.approx(2 * np.pi * 0.7, rel=5e-3)
    assert fit.handedness == 1
    assert 0.005 < fit.rms_residual < 0.02


def test_fit_straight_line_raises():
    line = np.linspace([0, 0, 0], [1, 2, 3], 10)
    with pytest.raises(InvalidParameterError, match="collinear"):
        fit_helix(line)
    with pytest.raises(InvalidParameterError, match="at least 5"):
        fit_helix(line[:4])


@pytest.mark.parametrize(
    ("kappa", "tau", "expected"),
    [
        (0.0, 0.0, Morphology.STRAIGHT),
        (0.0, 1.0, Morphology.TWISTED_ROD),
        (0.5, 0.1, Morphology.COIL),
        (0.1, 0.5, Morphology.HELIX),
        (0.01, 1.0, Morphology.TWISTED_ROD),
        (0.5, 0.0, Morphology.COIL),
    ],
)
def test_classify(kappa, tau, expected):
    assert classify_morphology(kappa, tau, length=50.0) is expected


def test_classify_rejects_bad_values():
    with pytest.raises(InvalidParameterError, match="curvature"):
        classify_morphology(-1.0, 0.0, length=1.0)
    with pytest.raises(InvalidParameterError, match="length"):
        classify_morphology(1.0, 0.0, length=0.0)


def test_polyline_morphology_of_exact_shapes():
    assert polyline_morphology(helix_points(2.0, 0.3, 3, 200)) is Morphology.COIL
    assert polyline_morphology(helix_points(0.5, 3.0, 3, 200)) is Morphology.HELIX
    line = np.linspace([0, 0, 0], [50, 0, 0], 51)
    assert polyline_morphology(line) is Morphology.STRAIGHT
    d1 = space_parallel_directors(line)
    t = np.tile([1.0, 0.0, 0.0], (50, 1))
    twisted = rotate_about_tangent(d1, t, 0.2 * np.arange(50))
    assert polyline_morphology(line, twisted) is Morphology.TWISTED_ROD
