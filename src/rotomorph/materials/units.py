"""Units of the values in materials files and measurement tables, and their conversions.

Every value a lab gives rotomorph carries its unit. Each *dimension* below has one canonical
unit (the package's: mm, s, MPa, °C) and a few spellings a lab is likely to write; values in
any of them are converted on reading, anything else is refused with the accepted spellings::

    >>> to_canonical("speed", 180.0, "mm/min")
    3.0
    >>> to_canonical("temperature", 448.15, "K")
    175.0

Temperatures are affine (K → °C subtracts 273.15); a *spread* of a temperature converts with
the scale alone (:func:`spread_to_canonical`).
"""

from __future__ import annotations

from typing import Final

from rotomorph.errors import InvalidParameterError

__all__ = [
    "CANONICAL",
    "DIMENSIONS",
    "accepted_units",
    "spread_to_canonical",
    "to_canonical",
]

#: Spellings of each dimension: unit → (scale, offset) with canonical = value · scale + offset.
DIMENSIONS: Final[dict[str, dict[str, tuple[float, float]]]] = {
    "speed": {"mm/s": (1.0, 0.0), "mm/min": (1.0 / 60.0, 0.0), "m/s": (1000.0, 0.0)},
    "curvature": {"1/mm": (1.0, 0.0), "1/cm": (0.1, 0.0), "1/m": (1e-3, 0.0)},
    "length": {"mm": (1.0, 0.0), "um": (1e-3, 0.0), "µm": (1e-3, 0.0), "cm": (10.0, 0.0)},
    "modulus": {
        "MPa": (1.0, 0.0),
        "kPa": (1e-3, 0.0),
        "GPa": (1e3, 0.0),
        "Pa": (1e-6, 0.0),
        "N/mm2": (1.0, 0.0),
    },
    "temperature": {
        "C": (1.0, 0.0),
        "°C": (1.0, 0.0),
        "degC": (1.0, 0.0),
        "K": (1.0, -273.15),
    },
    "density": {"g/cm3": (1.0, 0.0), "kg/m3": (1e-3, 0.0), "g/mL": (1.0, 0.0)},
    "ratio": {"1": (1.0, 0.0)},
    "percent": {"%": (1.0, 0.0)},
}

#: The canonical unit of each dimension (the one values are stored and written in).
CANONICAL: Final[dict[str, str]] = {dim: next(iter(units)) for dim, units in DIMENSIONS.items()}


def accepted_units(dimension: str) -> tuple[str, ...]:
    """The spellings accepted for ``dimension`` (canonical first)."""
    try:
        return tuple(DIMENSIONS[dimension])
    except KeyError:
        raise InvalidParameterError("dimension", f"unknown dimension {dimension!r}") from None


def _factor(dimension: str, unit: str, field: str) -> tuple[float, float]:
    units = DIMENSIONS.get(dimension)
    if units is None:
        raise InvalidParameterError("dimension", f"unknown dimension {dimension!r}")
    key = unit.strip()
    if key not in units:
        listed = ", ".join(repr(u) for u in units)
        shown = key if key.isprintable() else key.encode("unicode_escape").decode("ascii")
        raise InvalidParameterError(
            field, f"{shown!r} is not a unit of {dimension}; use one of {listed}"
        )
    return units[key]


def to_canonical(dimension: str, value: float, unit: str, field: str = "unit") -> float:
    """``value`` given in ``unit`` expressed in the canonical unit of ``dimension``.

    Raises
    ------
    InvalidParameterError
        ``unit`` is not one of :func:`accepted_units` (field ``field``).
    """
    scale, offset = _factor(dimension, unit, field)
    return float(value) * scale + offset


def spread_to_canonical(dimension: str, spread: float, unit: str, field: str = "unit") -> float:
    """A standard deviation given in ``unit`` in the canonical unit (scale only, no offset)."""
    scale, _ = _factor(dimension, unit, field)
    return float(spread) * scale
