"""Print programs: the α sign convention, rotation, active side, validation."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rotomorph.design.path import Arc, Line, Path, Sinusoid, chain_segments, tangent_headings
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidDesignError


def test_straight_path_with_rotating_nozzle_gives_minus_omega_over_v():
    v, w = 3.0, 2.5
    prog = PrintProgram.from_rotation(Path.line((0, 0, 0), (10, 0, 0), 0.1), v, w)
    s_mid = 0.5 * (prog.arc_length[1:] + prog.arc_length[:-1])
    slope = np.diff(prog.interface_angle) / np.diff(s_mid)
    np.testing.assert_allclose(slope, -w / v, rtol=1e-12)
    np.testing.assert_allclose(prog.rotation, w, rtol=1e-12)
    np.testing.assert_allclose(prog.rotation_number, 0.3 * w / v, rtol=1e-12)


def test_fixed_nozzle_on_a_circle_turns_the_interface_with_the_heading():
    path = Path.from_segments([Arc(5.0, np.pi)], spacing=0.1)
    prog = PrintProgram.from_rotation(path, 1.0, 0.0, initial_angle=0.3)
    np.testing.assert_allclose(prog.interface_angle, path.heading - 0.3, atol=1e-12)


@pytest.mark.parametrize("angle", [1.5, -1.5])
def test_fixed_nozzle_on_an_arc_winds_minus_r_over_r_arc_at_every_vertex(angle):
    # the ends included: their vertex headings are the end edges' (one-sided), which alone
    # would give the first and last vertices half and the next ones three quarters of it
    r_arc = 4.0
    path = Path.from_segments([Arc(r_arc, angle)], spacing=0.05)
    fixed = PrintProgram.from_rotation(path, 3.0, 0.0)
    omega_star = fixed.radius * fixed.director_rotation / fixed.speed
    # chords of a uniformly sampled arc: Δ/chord = (1 + Δ²/24 + ...) / r_arc, Δ = 0.0125
    np.testing.assert_allclose(omega_star, -np.sign(angle) * fixed.radius / r_arc, rtol=1e-5)
    # a nozzle that tracks the heading winds nothing, ends included
    tracking = PrintProgram.from_interface_angle(path, 3.0, 0.4)
    assert np.all(tracking.director_rotation == 0.0)


def test_straight_path_director_rotation_is_the_nozzle_rotation_ends_included():
    # a rotation that changes along the path: the end vertices keep their own rates
    path = Path.line((0, 0, 0), (3, 4, 0), 0.1)
    prog = PrintProgram.from_rotation(path, 2.0, lambda s: 1.0 + 0.8 * s)
    np.testing.assert_allclose(prog.director_rotation, prog.rotation, rtol=1e-12)


def test_interface_normal_sign_convention():
    # nozzle normal along lab +y on a path along +x: lands on the left side (n = -d2, α = -π/2)
    prog = PrintProgram(Path.line((0, 0, 0), (1, 0, 0), 0.5).points, 1.0, np.pi / 2)
    np.testing.assert_allclose(prog.interface_normals, [[0, 1, 0]] * 2, atol=1e-12)
    np.testing.assert_allclose(prog.interface_angle, -np.pi / 2)


@pytest.mark.parametrize(("side", "sign"), [("outer", -1.0), ("inner", 1.0)])
def test_active_side_is_kept_outer_or_inner_and_flips(side, sign):
    path = Path.from_segments([Sinusoid(1.0, 5.0, 2)], spacing=0.05)
    prog = PrintProgram.sinusoid_with_active_side(path, 3.0, side)
    pts, kappa = path.points, path.curvature
    t = path.tangents
    centre_dir = np.cross([0, 0, 1.0], t) * np.sign(0.5 * (kappa[1:] + kappa[:-1]))[:, None]
    strong = np.abs(0.5 * (kappa[1:] + kappa[:-1])) > 0.3 * np.abs(kappa).max()
    dots = np.einsum("ij,ij->i", prog.interface_normals, centre_dir)[strong]
    assert np.all(sign * dots > 0.99)
    # the in-plane normal flips at every inflection (3 interior ones in two periods)
    lateral = np.einsum("ij,ij->i", prog.interface_normals, np.cross([0, 0, 1.0], t))
    flips = np.sum(np.diff(np.sign(lateral[np.abs(lateral) > 0.9])) != 0)
    assert flips == 3
    assert len(pts) == len(prog.nozzle_angle)


def test_from_interface_angle_on_a_straight_path_roundtrips():
    path = Path.line((0, 0, 0), (5, 5, 0), 0.2)
    alpha = 0.4 + 0.3 * path.arc_length
    prog = PrintProgram.from_interface_angle(path, 2.0, alpha)
    np.testing.assert_allclose(prog.interface_angle, 0.5 * (alpha[1:] + alpha[:-1]), atol=1e-12)


@settings(max_examples=30, deadline=None)
@given(st.floats(-3, 3), st.floats(0.1, 10), st.floats(-np.pi, np.pi), st.floats(0.05, 2.0))
def test_interface_normals_are_unit_and_normal_to_the_path(w, v, a0, dz):
    pts = np.column_stack(
        [np.linspace(0, 5, 20), np.sin(np.linspace(0, 3, 20)), dz * np.linspace(0, 1, 20) ** 2]
    )
    prog = PrintProgram.from_rotation(pts, v, w, initial_angle=a0)
    n = prog.interface_normals
    t = prog.path.tangents
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", n, t), 0.0, atol=1e-12)
    assert np.all(np.abs(np.diff(prog.interface_angle)) < np.pi)


def test_validation_names_field_and_vertex():
    pts = Path.line((0, 0, 0), (3, 0, 0), 1.0).points
    with pytest.raises(
        InvalidDesignError, match=r"PrintProgram.speed: must be > 0 mm/s; got -2.0 at vertex 2"
    ):
        PrintProgram(pts, [1.0, 1.0, -2.0, 1.0], 0.0)
    with pytest.raises(InvalidDesignError, match=r"nozzle_angle.*vertex 1"):
        PrintProgram(pts, 1.0, [0.0, np.nan, 0.0, 0.0])
    with pytest.raises(InvalidDesignError, match="one value per vertex"):
        PrintProgram(pts, [1.0, 1.0], 0.0)
    with pytest.raises(InvalidDesignError, match="active_fraction"):
        PrintProgram(pts, 1.0, 0.0, active_fraction=1.5)
    with pytest.raises(InvalidDesignError, match="speed"):
        PrintProgram.from_rotation(pts, 0.0, 1.0)


def test_program_is_frozen_and_read_only():
    prog = PrintProgram(Path.line((0, 0, 0), (1, 0, 0), 0.5).points, 1.0, 0.0)
    with pytest.raises(ValueError, match="read-only"):
        prog.speed[0] = 2.0
    assert prog.duration == pytest.approx(1.0)
    assert prog.with_layer(2, 1.2).points[:, 2].tolist() == [1.2] * 3


def test_flip_length_limits_the_rotation_rate():
    path = Path.from_segments([Sinusoid(1.0, 5.0, 2)], spacing=0.05)
    step = PrintProgram.sinusoid_with_active_side(path, 3.0, "outer")
    smooth = PrintProgram.sinusoid_with_active_side(path, 3.0, "outer", flip_length=0.5)
    assert np.abs(step.rotation).max() > 60.0
    assert np.abs(smooth.rotation).max() < 3.0 * np.pi / 0.5 * 1.2
    # away from the inflections the active side is unchanged
    far = np.abs(path.curvature) > 0.5 * np.abs(path.curvature).max()
    np.testing.assert_allclose(smooth.nozzle_angle[far], step.nozzle_angle[far], atol=1e-9)
    with pytest.raises(InvalidDesignError, match="flip_length"):
        PrintProgram.sinusoid_with_active_side(path, 3.0, flip_length=-1.0)


def test_a_nozzle_tracking_an_arc_keeps_its_interface_angle_to_the_arcs_end():
    segs = [Line(10.0), Arc(60.0, -np.pi / 4)]
    pts, owner = chain_segments(segs, start=(10.0, 10.0, 0.0), spacing=1.0)
    psi = tangent_headings(segs, pts, owner)
    prog = PrintProgram.from_interface_angle(pts, 3.0, 0.5, tangent_heading=psi)
    assert prog.has_tangents
    np.testing.assert_array_equal(prog.vertex_heading, psi)
    np.testing.assert_allclose(prog.nozzle_angle[[-1, 10]], psi[[-1, 10]] - 0.5)
    np.testing.assert_allclose(prog.interface_angle, 0.5, atol=1e-12)  # every edge, the last too
    assert np.all(prog.director_rotation == 0.0)  # tracks the tangent: winds no helix
    # the vertex normals: α from d1 = +z toward d2 = t x d1 about the curve's tangent t
    t = np.column_stack([np.cos(psi), np.sin(psi), np.zeros_like(psi)])
    want = np.cos(0.5) * np.array([0.0, 0.0, 1.0]) + np.sin(0.5) * np.cross(t, [0.0, 0.0, 1.0])
    np.testing.assert_allclose(prog.vertex_interface_normals, want, atol=1e-12)
    # without the tangents the polygon's heading: the last chord lags the arc by half its turn
    plain = PrintProgram.from_interface_angle(pts, 3.0, 0.5)
    assert not plain.has_tangents
    half = 0.5 * np.pi / 4 / np.count_nonzero(owner[:-1] == 1)
    assert plain.nozzle_angle[-1] - prog.nozzle_angle[-1] == pytest.approx(half)
    assert plain.interface_angle[-1] - 0.5 == pytest.approx(-half / 2)
    with pytest.raises(InvalidDesignError, match="tangent_heading"):
        PrintProgram(pts, 3.0, 0.0, tangent_heading=psi[:-1])
    with pytest.raises(InvalidDesignError, match="tangent_heading"):
        PrintProgram.from_interface_angle(pts, 3.0, 0.5, tangent_heading=psi[1:])
