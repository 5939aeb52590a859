"""Checks of the run options of :func:`rotomorph.simulate.design.simulate_design`.

An option that does not apply to a design is refused, never ignored: a vertex spacing applies
to filaments; an actuation rule to lattices; temperatures and a filament model to filaments and
to lattices heated by a temperature-driven rule (``program``, the default, and ``thermal``),
not to the paper's x-readings (``literal``, ``swapped``, ``radius``, ``additive``), which ramp
x from 0 to 0.75. Values outside a physical range are refused with
the range (:data:`TEMPERATURE_RANGE`, :data:`MAX_STEPS`). The CLI (``rotomorph simulate``) and
the Python API run the same checks.
"""

from __future__ import annotations

import math
from typing import Any, Final

from rotomorph.errors import InvalidParameterError
from rotomorph.io.design_limits import LIMITS
from rotomorph.materials.temperature import ACTUATION_TEMPERATURE, PRINT_TEMPERATURE

__all__ = ["MAX_STEPS", "TEMPERATURE_ACTUATIONS", "TEMPERATURE_RANGE", "check_run_options"]

#: Accepted temperatures (°C): the materials' data cover printing to well above actuation.
TEMPERATURE_RANGE: Final = (-50.0, 300.0)
#: Lattice actuation rules ramped in temperature (the others ramp the paper's x).
TEMPERATURE_ACTUATIONS: Final = ("program", "thermal")
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
    from rotomorph.materials.natural import FilamentModel

    if model is not None and not isinstance(model, FilamentModel):
        raise InvalidParameterError(
            "model",
            f"must be a FilamentModel or the name of one ('calibrated', 'warner-terentjev', "
            f"'room-temperature'); got {model!r}",
        )
    if isinstance(steps, bool) or not isinstance(steps, int) or not 1 <= steps <= MAX_STEPS:
        raise InvalidParameterError(
            "steps", f"must be a whole number in [1, {MAX_STEPS}]; got {steps!r}"
        )
    if kind == "lattice":
        if spacing is not None:
            raise InvalidParameterError(
                "spacing",
                "applies to filaments only; a lattice's vertex spacing is its "
                "ghost_nodes field; remove it",
            )
        rule = "program" if actuation is None else actuation
        if rule not in TEMPERATURE_ACTUATIONS:
            for name, value in (
                ("temperature", temperature),
                ("start_temperature", start_temperature),
                ("model", model),
            ):
                if value is not None:
                    raise InvalidParameterError(
                        name,
                        f"does not apply to the {rule!r} actuation, which ramps the paper's x "
                        "from 0 to 0.75; remove it, or use a temperature-driven actuation "
                        "(program, thermal)",
                    )
    elif actuation is not None:
        raise InvalidParameterError(
            "actuation",
            "applies to lattices only; filaments are heated over a temperature ramp "
            "(temperature, start_temperature); remove it",
        )
    lo, hi = TEMPERATURE_RANGE
    for name, value in (("start_temperature", start_temperature), ("temperature", temperature)):
        if value is not None and not lo <= _number(name, value, "°C") <= hi:
            raise InvalidParameterError(name, f"must lie in [{lo:g}, {hi:g}] °C; got {value!r}")
    start = PRINT_TEMPERATURE if start_temperature is None else start_temperature
    end = ACTUATION_TEMPERATURE if temperature is None else temperature
    if (start_temperature is not None or temperature is not None) and not start < end:
        if temperature is not None:
            raise InvalidParameterError(
                "temperature",
                f"must exceed the start temperature {start:g} °C (the ramp heats from it to "
                f"this); got {end:g} °C",
            )
        raise InvalidParameterError(
            "start_temperature",
            f"must be below the final temperature {end:g} °C (the default; give a higher "
            f"temperature to start this warm); got {start:g} °C",
        )
    if spacing is not None:
        limit = LIMITS["vertex_spacing"]
        if not limit.minimum <= _number("spacing", spacing, "mm") <= limit.maximum:
            raise InvalidParameterError(
                "spacing", f"must lie in [{limit.minimum:g}, {limit.maximum:g}] mm; got {spacing!r}"
            )
