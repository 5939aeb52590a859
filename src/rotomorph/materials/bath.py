"""Density of the bath the filaments are actuated in (buoyancy of a lattice resting on the floor).

The table ``data/bath_fluids.toml`` lists each fluid's density at a reference temperature, its
volumetric thermal expansion coefficient and the source; the density at temperature ``T`` is
``rho_ref / (1 + beta (T - T_ref))``.
"""

from __future__ import annotations

import math
import sys
from importlib import resources
from typing import Any

from rotomorph.errors import InvalidParameterError

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

__all__ = ["bath_density", "bath_fluids"]


def bath_fluids() -> dict[str, dict[str, Any]]:
    """Entries of the bath-fluid table by name (density g/cm³, expansion 1/K, source)."""
    path = resources.files("rotomorph.materials").joinpath("data/bath_fluids.toml")
    return tomllib.loads(path.read_text("utf-8"))


def bath_density(name: str = "silicone_oil", temperature: float | None = None) -> float:
    """Density of bath fluid ``name`` (g/cm³) at ``temperature`` (°C; default its reference).

    Raises
    ------
    InvalidParameterError
        Unknown fluid (the message lists the known ones) or a temperature that is not finite.
    """
    fluids = bath_fluids()
    if name not in fluids:
        raise InvalidParameterError(
            "bath_density.name", f"unknown fluid {name!r}; known: {', '.join(sorted(fluids))}"
        )
    row = fluids[name]
    rho, beta, t_ref = (float(row[k]) for k in ("density", "expansion", "reference_temperature"))
    if temperature is None:
        return rho
    t = float(temperature)
    if not math.isfinite(t):
        raise InvalidParameterError("bath_density.temperature", f"must be finite (°C); got {t}")
    return rho / (1.0 + beta * (t - t_ref))
