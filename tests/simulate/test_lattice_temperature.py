"""Lattices heated by a temperature-driven actuation take the same temperature ramp and
filament model options as filaments; the paper's x-readings refuse them."""

from __future__ import annotations

import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.io.designfile import parse_design
from rotomorph.materials.natural import named_model
from rotomorph.simulate.design import simulate_design

DESIGN = parse_design(
    {"schema_version": 1, "lattice": {"n": 2, "pattern": "expanding", "ghost_nodes": 6}}
)


@pytest.fixture(scope="module")
def hot():
    return simulate_design(DESIGN, steps=1)


def test_the_default_ramp_is_25_to_175_degrees(hot):
    assert list(hot.scalars["temperature"]) == [25.0, 175.0]
    assert hot.scalars["area_ratio"][-1] > 1.05  # the expanding pattern expands when hot


def test_a_lower_final_temperature_actuates_less(hot):
    warm = simulate_design(DESIGN, steps=1, temperature=100.0)
    assert list(warm.scalars["temperature"]) == [25.0, 100.0]
    assert 1.0 <= warm.scalars["area_ratio"][-1] < hot.scalars["area_ratio"][-1]


def test_the_filament_model_reaches_the_lattice(hot):
    other = simulate_design(DESIGN, steps=1, model=named_model("room-temperature"))
    assert abs(other.scalars["area_ratio"][-1] - hot.scalars["area_ratio"][-1]) > 1e-3


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"actuation": "swapped", "temperature": 150.0}, "temperature"),
        ({"actuation": "additive", "start_temperature": 20.0}, "start_temperature"),
        ({"actuation": "literal", "model": named_model("calibrated")}, "model"),
        ({"temperature": 20.0}, "temperature"),  # below the print temperature
        ({"spacing": 0.5}, "spacing"),
    ],
)
def test_options_that_do_not_apply_are_refused(options, field):
    with pytest.raises(InvalidParameterError) as err:
        simulate_design(DESIGN, steps=1, **options)
    assert err.value.field == field
