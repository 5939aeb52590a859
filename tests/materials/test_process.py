"""Process model: kinematics, order parameter, actuation strains, temperature."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.materials import (
    EmpiricalThreshold,
    WarnerTerentjev,
    actuation_fraction,
    dimensionless_rotation,
    helix_angle,
    helix_angle_profile,
    order_parameter,
)
from rotomorph.materials.process import backbone_anisotropy, strain_to_stretch, stretch_to_strain


def test_kinematics_table_of_notes() -> None:
    # reference values: v = 3 mm/s, R = 0.3 mm: omega = 0.6, 2.5, 10, 20 rad/s
    w = dimensionless_rotation(np.array([0.6, 2.5, 10.0, 20.0]), 3.0, 0.3)
    np.testing.assert_allclose(w, [0.06, 0.25, 1.0, 2.0])
    np.testing.assert_allclose(np.degrees(helix_angle(w)), [3.43, 14.04, 45.0, 63.43], atol=0.01)
    assert dimensionless_rotation(-10.0, 3.0, 0.3) == pytest.approx(-1.0)
    # profile: surface value atan(w), zero on the axis, monotone
    r = np.linspace(0, 0.3, 7)
    phi = helix_angle_profile(r, 0.3, 2.0)
    assert phi[0] == 0.0 and phi[-1] == pytest.approx(math.atan(2.0))
    assert np.all(np.diff(phi) > 0)
    np.testing.assert_allclose(np.tan(phi), 2.0 * r / 0.3, atol=1e-14)


@pytest.mark.parametrize("bad", [0.0, -1.0, float("nan")])
def test_bad_speed_raises(bad: float) -> None:
    with pytest.raises(InvalidParameterError, match="speed"):
        dimensionless_rotation(1.0, bad, 0.3)
    with pytest.raises(InvalidParameterError, match="speed"):
        order_parameter(bad)


def test_order_parameter_log_interpolation() -> None:
    np.testing.assert_allclose(order_parameter(np.array([0.25, 3.0])), [0.150, 0.230], atol=1e-12)
    # reference values: S(0.5) = 0.172, S(1.75) = 0.213, S = 0.1946 + 0.0322 ln v
    assert order_parameter(0.5) == pytest.approx(0.172, abs=6e-4)
    assert order_parameter(1.75) == pytest.approx(0.213, abs=6e-4)
    assert order_parameter(1.0) == pytest.approx(0.1946, abs=2e-4)
    # three points: piecewise linear in ln v passes through the middle point
    pts = ((0.25, 0.15), (1.0, 0.2), (3.0, 0.23))
    assert order_parameter(1.0, pts) == pytest.approx(0.2)
    assert 0.0 <= order_parameter(1e-12) <= order_parameter(0.01)


def test_warner_terentjev_table_of_notes() -> None:
    # reference: Q = 0.15, 0.23 -> lambda_par 0.868, 0.808; eng d = -0.206, -0.305
    r = backbone_anisotropy(np.array([0.15, 0.23]))
    np.testing.assert_allclose(r ** (-1 / 3), [0.868, 0.808], atol=6e-4)
    eng = WarnerTerentjev(measure="engineering")
    hen = WarnerTerentjev(measure="hencky")
    p, q = eng.active_strains(np.array([0.25, 3.0]))
    np.testing.assert_allclose(p - q, [-0.206, -0.305], atol=1.5e-3)
    np.testing.assert_allclose(q, [0.073, 0.113], atol=1.5e-3)
    p, q = hen.active_strains(np.array([0.25, 3.0]))
    np.testing.assert_allclose(p - q, [-0.212, -0.320], atol=1.5e-3)
    np.testing.assert_allclose(p + 2 * q, 0.0, atol=1e-14)  # volume preserving
    assert stretch_to_strain(strain_to_stretch(-0.2, "hencky"), "hencky") == pytest.approx(-0.2)
    with pytest.raises(InvalidParameterError, match="measure"):
        WarnerTerentjev(measure="green")  # type: ignore[arg-type]


def test_empirical_threshold() -> None:
    m = EmpiricalThreshold(gain=2.0, threshold=0.15)
    p, q = m.active_strains(np.array([0.25, 3.0]))
    np.testing.assert_allclose(p, [0.0, -0.16], atol=1e-12)
    np.testing.assert_allclose(q, -0.5 * p)
    p, q = EmpiricalThreshold(gain=2.0, threshold=0.15, measure="engineering").active_strains(3.0)
    assert (1 + p) * (1 + q) ** 2 == pytest.approx(1.0)


def test_actuation_fraction_sigmoid_and_hysteresis() -> None:
    t = np.linspace(20, 180, 81)
    x = actuation_fraction(t, 90.0, 10.0)
    assert np.all(np.diff(x) > 0) and x[0] < 1e-3 and x[-1] > 0.999
    assert actuation_fraction(90.0, 90.0, 10.0) == pytest.approx(0.5)
    heat = actuation_fraction(t, 90.0, 5.0, hysteresis=20.0)
    cool = actuation_fraction(t, 90.0, 5.0, direction="cooling", hysteresis=20.0)
    assert np.all(cool >= heat)  # the cooling branch lags: still actuated at lower T
    assert actuation_fraction(100.0, 90.0, 5.0, hysteresis=20.0) == pytest.approx(0.5)
    assert actuation_fraction(80.0, 90.0, 5.0, direction="cooling", hysteresis=20.0) == (
        pytest.approx(0.5)
    )
    np.testing.assert_allclose(
        actuation_fraction(t, 90.0, 5.0, direction="cooling"), actuation_fraction(t, 90.0, 5.0)
    )


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"temperature": -300.0}, "temperature"),
        ({"temperature": float("nan")}, "temperature"),
        ({"width": 0.0}, "width"),
        ({"hysteresis": -1.0}, "hysteresis"),
        ({"direction": "up"}, "direction"),
    ],
)
def test_actuation_fraction_bad_inputs(kwargs: dict, field: str) -> None:
    args = {"temperature": 100.0, "transition_temperature": 90.0, "width": 5.0}
    args.update(kwargs)
    with pytest.raises(InvalidParameterError, match=field):
        actuation_fraction(**args)
