"""Closed-form free-filament helix."""

from __future__ import annotations

import math

import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.materials import free_helix


def test_helix_geometry_round_trip() -> None:
    a, b = 0.7, 0.2  # helix x = a cos s', y = a sin s', z = b s' (pitch 2 pi b)
    k, t = a / (a * a + b * b), b / (a * a + b * b)
    shape = free_helix(k, t)
    assert shape.radius == pytest.approx(a)
    assert shape.pitch == pytest.approx(2 * math.pi * b)
    assert shape.end_to_end_ratio == pytest.approx(b / math.hypot(a, b))
    assert shape.label == "coil" and shape.morphology_parameter == pytest.approx(a / b)
    left = free_helix(k, -t)
    assert left.pitch == pytest.approx(-shape.pitch) and left.radius == pytest.approx(a)


def test_labels_and_limits() -> None:
    assert free_helix(0.0, 0.0).label == "straight"
    rod = free_helix(0.0, 2.0, -0.2)
    assert rod.label == "twisted rod" and rod.end_to_end_ratio == pytest.approx(math.exp(-0.2))
    assert free_helix(0.1, 2.0).label == "helix"
    ring = free_helix(2.0, 0.0)
    assert ring.label == "coil" and ring.radius == pytest.approx(0.5) and ring.end_to_end_ratio == 0
    # small Lambda: L/L0 ~ 1 - Lambda^2/2
    assert free_helix(0.01, 1.0).end_to_end_ratio == pytest.approx(1 - 0.5e-4, rel=1e-8)
    eng = free_helix(0.0, 1.0, -0.2, measure="engineering")
    assert eng.end_to_end_ratio == pytest.approx(0.8)
    with pytest.raises(InvalidParameterError):
        free_helix(float("nan"), 1.0)
    with pytest.raises(InvalidParameterError, match="stretch"):
        free_helix(1.0, 1.0, -1.5, measure="engineering")
