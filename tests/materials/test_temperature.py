"""Moduli and free strains between 25 °C and the actuation temperature (temperature laws)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.material import get_material
from rotomorph.materials.natural import FilamentModel, natural_field
from rotomorph.materials.temperature import (
    active_modulus,
    passive_modulus,
    passive_strain_fraction,
    temperature_laws,
)

LCE, ACR = get_material("lce"), get_material("acrylate")


def test_every_law_states_its_status_and_source():
    laws = {law.quantity: law for law in temperature_laws()}
    assert {"passive_modulus", "active_modulus", "active_strain", "passive_strain"} <= set(laws)
    assert {law.status for law in laws.values()} <= {"measured", "cited", "calibrated", "assumed"}
    assert all(len(law.source) > 20 for law in laws.values())
    assert laws["active_modulus_25C"].value == LCE.youngs_modulus
    assert laws["passive_modulus_25C"].value == ACR.youngs_modulus
    assert laws["active_modulus"].status == "assumed"


def test_moduli_run_from_the_measured_cold_ratio_to_the_calibrated_hot_one():
    model = FilamentModel()  # the temperature laws are the default
    assert model.temperature_dependent
    flat = FilamentModel(temperature_dependent=False)
    assert flat.moduli(LCE, ACR, 25.0) == flat.moduli(LCE, ACR) == model.moduli(LCE, ACR)
    cold = model.moduli(LCE, ACR, 25.0)
    hot = model.moduli(LCE, ACR, 175.0)
    assert cold[1] == pytest.approx(0.57)
    assert cold[0] / cold[1] == pytest.approx(29.67 / 0.57, rel=0.01)  # x(25 °C) ~ 1e-3
    assert hot[0] / hot[1] == pytest.approx(model.modulus_ratio, rel=1e-3)
    # entropic passive ink: E proportional to absolute temperature
    assert hot[1] == pytest.approx(0.57 * 448.15 / 298.15)
    ratios = [np.divide(*model.moduli(LCE, ACR, t)) for t in np.linspace(25, 175, 16)]
    assert np.all(np.diff(ratios) <= 1e-12)  # the LCE softens through the transition
    assert passive_modulus(1.0, 25.0) == 1.0
    assert active_modulus(30.0, 2.0, 0.0) == pytest.approx(30.0)
    assert active_modulus(30.0, 2.0, 1.0) == pytest.approx(2.0)
    assert passive_strain_fraction(100.0) == pytest.approx(0.5)
    with pytest.raises(InvalidParameterError, match="temperature"):
        passive_modulus(1.0, -300.0)


def test_a_temperature_ramp_bends_a_janus_filament_progressively():
    s = np.linspace(0.0, 4.0, 21)
    from tests.materials.test_natural import Program

    prog = Program(np.column_stack([s, 0 * s, 0 * s]), np.full(21, 3.0), np.zeros(21), np.zeros(20))
    model = FilamentModel(resolution=48, temperature_dependent=True)
    k = [natural_field(prog, temperature=t, model=model).curvature1[0] for t in (25, 80, 100, 175)]
    assert abs(k[0]) < 0.02 and np.all(np.diff(k) > 0) and k[-1] > 0.4
    # passive expansion starts at once (linear in T), the LCE only through its transition
    low = model.strains_at(3.0, LCE, ACR, 50.0)
    assert low[2] == pytest.approx(model.passive_strain / 6)
    assert abs(low[0]) < 0.1 * abs(model.strains(3.0, ACR)[0])
