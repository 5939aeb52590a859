"""Every value of a materials file: its dimension, its conversion to canonical units, and the
range it can lie in.

A materials file gives each value with its unit (:mod:`rotomorph.materials.units` lists the
accepted ones); :func:`convert_value` turns it into the canonical unit of its key's dimension
(:data:`DIMENSION`), and :func:`check_range` refuses a value outside the range an elastomer
ink printed and heated can have (:data:`RANGE`), or an interval that does not hold its value.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Final

from rotomorph.errors import InvalidParameterError
from rotomorph.materials.units import CANONICAL, spread_to_canonical, to_canonical

if TYPE_CHECKING:
    from rotomorph.materials.materials_schema import Value

__all__ = ["DIMENSION", "RANGE", "SPEED_RANGE", "check_range", "convert_value"]

#: Dimension (units module) of each value key; ``"interval"`` values follow the same unit.
DIMENSION: Final[dict[str, str]] = {
    "youngs_modulus": "modulus",
    "actuated_modulus_ratio": "ratio",
    "poisson_ratio": "ratio",
    "glass_transition": "temperature",
    "transition_temperature": "temperature",
    "transition_width": "temperature_difference",
    "hysteresis": "temperature_difference",
    "density": "density",
    "free_length": "ratio",
    "free_strain": "ratio",
    "strain_gain": "ratio",
    "strain_threshold": "ratio",
    "order_scale": "ratio",
    "director_pitch": "ratio",
    "print_temperature": "temperature",
    "actuation_temperature": "temperature",
    "outlet_diameter": "length",
    "filament_radius": "length",
    "active_fraction": "ratio",
}


def convert_value(key: str, v: Value) -> Value:
    """``v`` in the canonical unit of ``key``'s dimension (units module)."""
    dim = DIMENSION[key]
    if dim == "temperature_difference":  # a width: K and °C differ by scale 1 only
        base = {"C": 1.0, "°C": 1.0, "degC": 1.0, "K": 1.0}
        if v.unit.strip() not in base:
            raise ValueError(
                f"{key}.unit: {v.unit!r} is not a temperature difference; use 'C' or 'K'"
            )
        return v.model_copy(update={"unit": "C"})
    try:
        value = to_canonical(dim, v.value, v.unit)
        sd = None if v.sd is None else spread_to_canonical(dim, v.sd, v.unit)
        interval = (
            None if v.interval is None else [to_canonical(dim, x, v.unit) for x in v.interval]
        )
    except InvalidParameterError as err:
        raise ValueError(f"{key}.unit: {str(err).split(': ', 1)[-1]}") from None
    return v.model_copy(
        update={"value": value, "sd": sd, "interval": interval, "unit": CANONICAL[dim]}
    )


#: Where each value can lie for an ink printed and heated as an elastomer (canonical units;
#: ``(low, high, unit, low included)``): temperatures an elastomer ink sees, moduli up to a
#: stiff thermoset's, strain-law coefficients of order one. Outside them a value is a typing
#: error (a unit or a decimal point), not a material.
RANGE: Final[dict[str, tuple[float, float, str, bool]]] = {
    "print_temperature": (-200.0, 500.0, "°C", True),
    "actuation_temperature": (-200.0, 500.0, "°C", True),
    "glass_transition": (-200.0, 500.0, "°C", True),
    "transition_temperature": (-200.0, 500.0, "°C", True),
    "transition_width": (0.0, 200.0, "°C", False),
    "hysteresis": (0.0, 200.0, "°C", True),
    "youngs_modulus": (1e-4, 1e5, "MPa", True),
    "actuated_modulus_ratio": (1e-4, 1e4, "", True),
    "strain_gain": (0.0, 100.0, "", False),
    "order_scale": (0.0, 100.0, "", False),
    "strain_threshold": (-1.0, 1.0, "", True),
    "outlet_diameter": (0.02, 20.0, "mm", True),
}
#: Print speeds of an order-parameter curve (mm/s): the design files' speed range.
SPEED_RANGE: Final = (0.01, 500.0)


def check_range(key: str, v: Value) -> None:
    """Raise ``ValueError`` naming ``key`` when its value (canonical units) leaves
    :data:`RANGE`, or its interval does not hold it."""
    if key in RANGE:
        lo, hi, unit, closed = RANGE[key]
        if not ((lo <= v.value) if closed else (lo < v.value)) or not v.value <= hi:
            left = "[" if closed else "("
            raise ValueError(
                f"{key}.value: must lie in {left}{lo:g}, {hi:g}]{' ' + unit if unit else ''}; "
                f"got {v.value:g}"
            )
    if v.interval is not None and not v.interval[0] <= v.value <= v.interval[1]:
        raise ValueError(
            f"{key}.interval: must be [low, high] around the value {v.value:g}; got "
            f"[{v.interval[0]:g}, {v.interval[1]:g}]"
        )
