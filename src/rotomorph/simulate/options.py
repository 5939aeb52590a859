"""Checks of the run options of :func:`rotomorph.simulate.design.simulate_design`.

An option that does not apply to a design is refused, never ignored: temperatures, a vertex
spacing and a filament model apply to filaments (heated over a temperature ramp); an actuation
rule applies to lattices (ramped by that rule). Values outside a physical range are refused with
the range (:data:`TEMPERATURE_RANGE`, :data:`MAX_STEPS`). The CLI (``rotomorph simulate``) and
the Python API run the same checks.
"""

from __future__ import annotations

import math
from typing import Any, Final

from rotomorph.errors import InvalidParameterError

__all__ = ["MAX_STEPS", "TEMPERATURE_RANGE", "check_run_options"]

#: Accepted temperatures (°C): the materials' data cover printing to well above actuation.
TEMPERATURE_RANGE: Final = (-50.0, 300.0)
#: Most heating steps of one run.
MAX_STEPS: Final = 10_000


def _number(name: str, value: Any, unit: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidParameterError(name, f"must be a number ({unit}); got {value!r}")
    if not math.isfinite(value):
        raise InvalidParameterError(name, f"must be finite ({unit}); got {value!r}")
    return float(value)


def check_run_options(
    kind: str,
    *,
    steps: Any,
    start_temperature: Any = None,
    temperature: Any = None,
    spacing: Any = None,
    model: Any = None,
    actuation: Any = None,
) -> None:
    """Refuse options that do not apply to a design of ``kind`` or lie out of range.

    Parameters
    ----------
    kind
        ``"filaments"`` or ``"lattice"``.
    steps, start_temperature, temperature, spacing, model, actuation
        As :func:`rotomorph.simulate.design.simulate_design`; ``None`` means not given.

    Raises
    ------
    InvalidParameterError
        Naming the option and the fix.
    """
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
        raise InvalidParameterError(
            "steps", f"must be a whole number in [1, {MAX_STEPS}]; got {steps!r}"
        )
    if kind == "lattice":
        for name, value in (
            ("temperature", temperature),
            ("start_temperature", start_temperature),
            ("spacing", spacing),
            ("model", model),
        ):
            if value is not None:
                raise InvalidParameterError(
                    name,
                    "applies to filaments only; a lattice is ramped by its actuation rule "
                    "(actuation); remove it",
                )
        return
    if actuation is not None:
        raise InvalidParameterError(
            "actuation",
            "applies to lattices only; filaments are heated over a temperature ramp "
            "(temperature, start_temperature); remove it",
        )
    lo, hi = TEMPERATURE_RANGE
    for name, value in (("start_temperature", start_temperature), ("temperature", temperature)):
        if value is not None and not lo <= _number(name, value, "°C") <= hi:
            raise InvalidParameterError(name, f"must lie in [{lo:g}, {hi:g}] °C; got {value!r}")
    if spacing is not None:
        _number("spacing", spacing, "mm")
