"""Assembly of the natural field of one filament (Frame A) and its closed-form shape."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np
import pytest

from rotomorph import geometry
from rotomorph.errors import InvalidDesignError, InvalidParameterError, MaterialError
from rotomorph.materials import FilamentModel, NaturalField, filament_section, natural_field
from rotomorph.materials.calibrate import filament_shapes
from rotomorph.materials.closed_form import janus_curvature

R = 0.3
# full-actuation moduli and x(T)-scaled eigenstrains (the default): the exact relations below
MODEL = FilamentModel(resolution=64, temperature_dependent=False)


@dataclass(frozen=True)
class Program:
    """Local stand-in for rotomorph.design.program.PrintProgram (same attribute names)."""

    points: np.ndarray
    speed: np.ndarray
    rotation: np.ndarray
    interface_angle: np.ndarray
    radius: float = R
    active_fraction: float = 0.5
    active_material: str = "lce"
    passive_material: str = "acrylate"


def straight(
    n: int = 41, length: float = 4.0, speed: float = 3.0, omega_star: float = 0.0
) -> Program:
    s = np.linspace(0.0, length, n)
    pts = np.column_stack([s, np.zeros(n), np.zeros(n)])
    rot = omega_star * speed / R
    mid = 0.5 * (s[:-1] + s[1:])
    # design-layer convention: alpha = psi - alpha_n, so d(alpha)/ds = -omega/v
    return Program(pts, np.full(n, speed), np.full(n, rot), -(rot / speed) * mid)


def test_straight_janus_without_rotation() -> None:
    prog = straight()
    nf = natural_field(prog, temperature=175.0, model=MODEL)
    assert isinstance(nf, NaturalField)
    np.testing.assert_allclose(nf.directors, np.tile([0.0, 0.0, 1.0], (40, 1)), atol=1e-14)
    sec = MODEL.section(*_inks(), R, 0.5, 175.0)  # moduli at the temperature
    eps_par, _, eps_p = MODEL.strains(3.0, _inks()[1])
    k_expected = janus_curvature(eps_p - eps_par, MODEL.modulus_ratio, R) * nf.actuation
    np.testing.assert_allclose(nf.curvature1, k_expected, rtol=5e-3)
    np.testing.assert_allclose(nf.curvature2, 0.0, atol=1e-9)
    np.testing.assert_allclose(nf.twist, 0.0, atol=1e-9)
    assert nf.actuation > 0.999
    np.testing.assert_allclose(nf.bending_stiffness1, sec.bending_stiffness1)
    assert np.all(nf.bending_stiffness1 < nf.bending_stiffness2)
    assert np.all(nf.rest_length < 0.1) and np.all(nf.axial_strain < 0)
    np.testing.assert_allclose(nf.rest_length, 0.1 * np.exp(nf.axial_strain))
    shape = nf.morphology()
    assert shape.label == "coil"
    # curvature per printed length: the radius grows back by the centre-line stretch
    assert shape.radius == pytest.approx(np.exp(nf.axial_strain[0]) / nf.curvature1[0])


def test_rotated_filament_matches_closed_form_helix() -> None:
    prog = straight(n=81, omega_star=0.25)
    nf = natural_field(prog, temperature=175.0, model=MODEL)
    section = MODEL.section(*_inks(), R, 0.5)
    e_par, e_perp, eps_p = MODEL.strains(3.0, _inks()[1])
    _, kappa, dtau = section.natural_strains(-0.25, e_par, e_perp, eps_p)
    x = nf.actuation
    assert dtau[0] > 0  # untwists the printed (negative) interface twist
    np.testing.assert_allclose(nf.twist, -0.25 / R + x * dtau[0], rtol=1e-6)
    # K_J toward the vertex normal, read in the two edges' frames (each turned by half the
    # interface rotation dα of an edge): the rod's curvature vector is exactly K_J toward n
    half = 0.5 * np.abs(np.diff(prog.interface_angle))
    np.testing.assert_allclose(nf.curvature1, x * kappa[0, 0] * np.cos(half), rtol=1e-6)
    # directors rotate with the interface angle about the tangent: n = cos a z + sin a (t x z)
    a = prog.interface_angle
    expected = np.column_stack([np.zeros_like(a), -np.sin(a), np.cos(a)])
    np.testing.assert_allclose(nf.directors, expected, atol=1e-12)
    shape = nf.morphology()
    ref = filament_shapes(MODEL, [0.25], 0.5)[0]
    assert shape.end_to_end_ratio == pytest.approx(ref.end_to_end_ratio, rel=1e-3)
    assert shape.label == ref.label
    # the same helix, not its mirror image: the closed form winds the director helix with the
    # design layer's sense, as the rod's natural field does
    assert shape.torsion == pytest.approx(ref.torsion, rel=1e-3)
    assert shape.curvature == pytest.approx(ref.curvature, rel=1e-3)


def test_opposite_rotation_convention_is_reported(caplog: pytest.LogCaptureFixture) -> None:
    prog = straight(omega_star=0.25)
    flipped = replace(prog, interface_angle=-prog.interface_angle)
    with caplog.at_level("WARNING", logger="rotomorph.materials.natural"):
        natural_field(prog, model=MODEL)
        assert not caplog.records
        natural_field(flipped, model=MODEL)
    assert "sign convention" in caplog.text


def test_cold_filament_keeps_printed_curvature_and_sign_of_actuation() -> None:
    # planar CCW arc of radius 1 mm (1/rho > K_J); active half on the outer side
    # (alpha = +90 deg: n = t x z points away from the centre)
    rho, n = 1.0, 61
    th = np.linspace(0.0, 1.5, n)
    pts = np.column_stack([rho * np.cos(th), rho * np.sin(th), np.zeros(n)])
    prog = Program(pts, np.full(n, 3.0), np.zeros(n), np.full(n - 1, math.pi / 2))
    d1 = geometry.space_parallel_directors(pts)
    np.testing.assert_allclose(d1[:, 2], 1.0)
    cold = natural_field(prog, temperature=25.0, model=MODEL)
    assert cold.actuation < 1e-2
    # n points outward, the centre of curvature lies at -n: curvature toward m1 is -1/rho
    k_exact = -2 * math.tan(0.5 * 1.5 / (n - 1)) / (2 * rho * math.sin(0.5 * 1.5 / (n - 1)))
    hot = natural_field(prog, temperature=175.0, model=MODEL)
    # the field is affine in the actuation fraction: extrapolate to x = 0 for the printed value
    base = cold.curvature1 - cold.actuation * (hot.curvature1 - cold.curvature1) / (
        hot.actuation - cold.actuation
    )
    np.testing.assert_allclose(base, k_exact, rtol=1e-9)
    assert k_exact == pytest.approx(-1 / rho, rel=1e-3)
    # heating an outer-active arc straightens it (|curvature| decreases)
    assert np.all(np.abs(hot.curvature1) < np.abs(cold.curvature1))
    np.testing.assert_allclose(hot.voronoi_length, 2 * rho * math.sin(0.75 / (n - 1)), rtol=1e-12)
    with pytest.raises(InvalidDesignError, match=r"varies|uniform"):
        replace(hot, twist=np.linspace(0, 1, n - 2)).morphology()


def test_pure_lce_has_no_curvature() -> None:
    prog = replace(straight(omega_star=1.0), active_fraction=1.0)
    nf = natural_field(prog, temperature=175.0, model=MODEL)
    np.testing.assert_allclose(nf.curvature1, 0.0, atol=1e-8)
    assert nf.morphology().label == "twisted rod"
    assert np.all(nf.twist < 1.0 / R)  # the eigen-twist untwists the printed helix


def test_moduli_and_room_temperature_ratio() -> None:
    lce, acr = _inks()
    assert FilamentModel(modulus_ratio=None).moduli(lce, acr) == (29.67, 0.57)
    ea, ep = MODEL.moduli(lce, acr)
    assert ea / ep == pytest.approx(MODEL.modulus_ratio)
    k52 = natural_field(straight(), model=FilamentModel(modulus_ratio=None, resolution=64))
    k4 = natural_field(straight(), model=MODEL)
    # the 25 C ratio gives a 2-4x smaller curvature
    assert 2.0 < k4.curvature1[0] / k52.curvature1[0] < 5.0
    assert filament_section(R, ea, ep, resolution=64) is MODEL.section(lce, acr, R, 0.5)


@pytest.mark.parametrize(
    ("change", "exc", "field"),
    [
        ({"speed": np.zeros(41)}, InvalidDesignError, "speed"),
        ({"rotation": np.zeros(5)}, InvalidDesignError, "rotation"),
        ({"radius": -0.3}, InvalidDesignError, "radius"),
        ({"active_fraction": 0.0}, InvalidDesignError, "active_fraction"),
        ({"active_material": "unobtainium"}, MaterialError, "known"),
        ({"passive_material": "lce"}, MaterialError, "passive"),
    ],
)
def test_bad_programs(change: dict, exc: type, field: str) -> None:
    with pytest.raises(exc, match=field):
        natural_field(replace(straight(), **change), model=MODEL)


def _inks():
    from rotomorph.materials import get_material

    return get_material("lce"), get_material("acrylate")


def test_default_model_is_the_stored_joint_calibration() -> None:
    # one default: simulate, paper, the lattice and the examples all use FilamentModel(),
    # whose parameters are the joint calibration's chosen fit (stored with their source)
    from rotomorph.materials.calibrate import paper_calibration
    from rotomorph.materials.natural import CALIBRATED, MODEL_NAMES, named_model

    chosen = paper_calibration().chosen.values
    assert set(chosen) == set(CALIBRATED)
    for name, value in chosen.items():
        assert CALIBRATED[name] == pytest.approx(value, rel=1e-6), name
    default = FilamentModel()
    assert default.modulus_ratio == CALIBRATED["modulus_ratio"]
    assert default.passive_strain == CALIBRATED["passive_strain"]
    assert named_model("calibrated") == default
    assert named_model("room-temperature").moduli(*_inks()) == (29.67, 0.57)
    assert set(MODEL_NAMES) == {"calibrated", "warner-terentjev", "room-temperature"}
    with pytest.raises(InvalidParameterError, match="model"):
        named_model("magic")
