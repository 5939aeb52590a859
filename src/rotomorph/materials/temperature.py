r"""Moduli and free strains of the two inks between 25 °C and the actuation temperature.

What is measured and what is assumed is stated, with sources, in
``data/model/temperature_laws.csv`` (:func:`temperature_laws`). In short, with T in °C,
T_K = T + 273.15, x(T) the nematic-isotropic fraction of
:func:`rotomorph.materials.process.actuation_fraction` and m the effective modulus ratio at
actuation:

* passive modulus, entropic rubber elasticity (Treloar 1975): :math:`E_p(T) = E_p(25)\,
  T_K / 298.15` (measured at 25 °C, law assumed);
* active modulus: measured at 25 °C (29.67 MPa, near its glass transition); at full actuation
  :math:`m\,E_p(T)` (calibrated); in between :math:`\ln E_a = (1 - x)\ln E_a(25) +
  x \ln(m E_p)` (assumed);
* LCE free strains :math:`x(T)\,\varepsilon_{full}` (assumed logistic, placeholder T_NI);
* passive free strain linear in T, :math:`\varepsilon_p (T - 25)/(175 - 25)` (thermal
  expansion; its 175 °C value is the model's ``passive_strain``).

Only the ratio E_a/E_p shapes a free filament; it runs from 52 (25 °C, measured) to m.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

from rotomorph.errors import InvalidParameterError

__all__ = [
    "PRINT_TEMPERATURE",
    "TemperatureLaw",
    "active_modulus",
    "passive_modulus",
    "passive_strain_fraction",
    "temperature_laws",
]

#: Temperature at which filaments are printed and the moduli are measured (°C).
PRINT_TEMPERATURE = 25.0
#: Temperature at which the calibrated full-actuation values apply (°C; paper, Fig. 2).
ACTUATION_TEMPERATURE = 175.0
_KELVIN = 273.15


@dataclass(frozen=True)
class TemperatureLaw:
    """One row of ``temperature_laws.csv``: a quantity, its law, status and source."""

    quantity: str
    law: str
    value: float | None
    unit: str
    status: str
    source: str


@lru_cache(maxsize=1)
def temperature_laws() -> tuple[TemperatureLaw, ...]:
    """The temperature laws with their status (measured / calibrated / assumed) and source."""
    text = resources.files("rotomorph.materials").joinpath("data/model/temperature_laws.csv")
    rows = csv.DictReader(io.StringIO(text.read_text("utf-8")))
    return tuple(
        TemperatureLaw(
            r["quantity"],
            r["law"],
            float(r["value"]) if r["value"] else None,
            r["unit"],
            r["status"],
            r["source"],
        )
        for r in rows
    )


def _kelvin(temperature: float) -> float:
    t = float(temperature)
    if not math.isfinite(t) or t <= -_KELVIN:
        raise InvalidParameterError("temperature", f"must be finite and > -273.15 °C; got {t}")
    return t + _KELVIN


def passive_modulus(modulus_25: float, temperature: float) -> float:
    """E_p(T) (MPa) of an entropic rubber measured at 25 °C (``modulus_25`` MPa)."""
    return modulus_25 * _kelvin(temperature) / (PRINT_TEMPERATURE + _KELVIN)


def active_modulus(modulus_25: float, hot_modulus: float, fraction: float) -> float:
    """E_a (MPa): log-linear in the actuation fraction x between the 25 °C and hot values.

    Parameters
    ----------
    modulus_25
        Measured E_a at 25 °C (MPa).
    hot_modulus
        E_a at full actuation at this temperature, m·E_p(T) (MPa).
    fraction
        x(T) ∈ [0, 1].
    """
    x = min(max(float(fraction), 0.0), 1.0)
    return math.exp((1.0 - x) * math.log(modulus_25) + x * math.log(hot_modulus))


def passive_strain_fraction(temperature: float) -> float:
    """(T - 25)/(175 - 25): share of the 175 °C passive strain reached at T (thermal expansion)."""
    _kelvin(temperature)
    return (float(temperature) - PRINT_TEMPERATURE) / (ACTUATION_TEMPERATURE - PRINT_TEMPERATURE)
