r"""Moduli and free strains of the two inks between 25 °C and the actuation temperature.

What is measured and what is assumed is stated, with sources, by :func:`temperature_laws`
(from the default materials file, ``data/paper_inks.toml``, which names the law of each ink:
``modulus_law``, ``strain_law``). In short, with T in °C,
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

import math
from dataclasses import dataclass
from functools import lru_cache

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


#: The temperature laws a materials file can name, in words (T in °C, x(T) the actuation
#: fraction, subscript 0 the print temperature, 1 the actuation temperature).
LAWS = {
    "entropic": (
        "E(T) = E(T0) (T + 273.15)/(T0 + 273.15)",
        "entropic rubber elasticity above T_g: modulus proportional to absolute temperature; "
        "Treloar, The Physics of Rubber Elasticity, 3rd ed., OUP 1975, ch. 4",
    ),
    "nematic-isotropic": (
        "ln E_a(T) = (1 - x(T)) ln E_a(T0) + x(T) ln(m E_p(T))",
        "log-linear between the measured cold and the calibrated hot value, following the "
        "nematic-isotropic fraction x(T); a modelling choice, no measurement in between",
    ),
    "logistic": (
        "eps(T) = x(T) eps_full; x(T) = 1/(1 + exp(-(T - T_NI)/w))",
        "logistic stand-in for the normalized length vs temperature through T_NI",
    ),
    "linear": (
        "eps_p(T) = eps_p (T - T0)/(T1 - T0)",
        "linear thermal expansion from the print temperature (eps_p at the actuation "
        "temperature T1)",
    ),
}


@dataclass(frozen=True)
class TemperatureLaw:
    """One quantity's law, value (or ``None``), unit, status and source."""

    quantity: str
    law: str
    value: float | None
    unit: str
    status: str
    source: str


@lru_cache(maxsize=1)
def temperature_laws() -> tuple[TemperatureLaw, ...]:
    """The temperature laws of the default inks with their status (cited / calibrated /
    assumed) and source, read from the default materials file."""
    from rotomorph.materials.parameter_set import default_materials

    paper = default_materials()
    lce, acr = paper.ink("lce"), paper.ink("acrylate")
    ratio = getattr(lce, "actuated_modulus_ratio")  # noqa: B009 - the active ink's field
    t_ni = getattr(lce, "transition_temperature")  # noqa: B009
    t_act = paper.document.conditions.actuation_temperature
    e_p, e_a = acr.youngs_modulus, lce.youngs_modulus

    def law(quantity: str, name: str, unit: str, extra: str = "") -> TemperatureLaw:
        text, why = LAWS[name]
        return TemperatureLaw(quantity, text, None, unit, "assumed", why + extra)

    return (
        TemperatureLaw(
            "passive_modulus_25C", "value", e_p.value, "MPa", e_p.provenance, e_p.source
        ),
        law("passive_modulus", acr.modulus_law, "MPa"),
        TemperatureLaw("active_modulus_25C", "value", e_a.value, "MPa", e_a.provenance, e_a.source),
        TemperatureLaw(
            "active_modulus_hot",
            "E_a(T) = m E_p(T) at full actuation",
            ratio.value,
            "1",
            ratio.provenance,
            f"m = the effective E_a/E_p: {ratio.source}",
        ),
        law("active_modulus", lce.modulus_law, "MPa"),
        law("active_strain", "logistic", "1", f"; T_NI: {t_ni.source}"),
        law("passive_strain", acr.strain_law, "1"),
        TemperatureLaw(
            "actuation_temperature", "value", t_act.value, "C", t_act.provenance, t_act.source
        ),
    )


def _kelvin(temperature: float) -> float:
    t = float(temperature)
    if not math.isfinite(t) or t <= -_KELVIN:
        raise InvalidParameterError("temperature", f"must be finite and > -273.15 °C; got {t}")
    return t + _KELVIN


def passive_modulus(
    modulus_25: float, temperature: float, reference: float = PRINT_TEMPERATURE
) -> float:
    """E_p(T) (MPa) of an entropic rubber measured at ``reference`` °C (``modulus_25`` MPa;
    default 25 °C)."""
    return modulus_25 * _kelvin(temperature) / _kelvin(reference)


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


def passive_strain_fraction(
    temperature: float,
    start: float = PRINT_TEMPERATURE,
    end: float = ACTUATION_TEMPERATURE,
) -> float:
    """(T - T_print)/(T_act - T_print), default (T - 25)/(175 - 25): share of the passive
    strain at the actuation temperature reached at T (linear thermal expansion)."""
    _kelvin(temperature)
    return (float(temperature) - start) / (end - start)
