"""The range the materials law was calibrated on: where the paper's filament measurements lie.

Print speeds of the Janus-curvature series (at ω* = 0) and rotation numbers of the L/L0 series
(at 3 mm/s), all heated to 175 °C, filaments of radius 0.3 mm with half (composite) or all
(pure LCE) of the section active, of the paper's two inks. A setting outside it is an
extrapolation of the fitted laws: ``rotomorph predict``, ``rotomorph simulate`` (its command
line, ``summary.json``, figure titles) and the paper report's rows say so
(:meth:`CalibratedRange.outside`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.materials.calibrate import PAPER_RADIUS, ROTATION_SERIES_SPEED
from rotomorph.materials.measurements import load_table

__all__ = [
    "CALIBRATED_FRACTIONS",
    "CALIBRATED_MATERIALS",
    "CALIBRATION_TEMPERATURE",
    "CalibratedRange",
    "calibrated_range",
]

#: Temperature (°C) at which every calibration group was measured (paper, Methods: filaments
#: heated from 25 to 175 °C and imaged there); the calibration is at full actuation.
CALIBRATION_TEMPERATURE = 175.0
#: Active shares of the section the paper measured: Janus composites and pure LCE.
CALIBRATED_FRACTIONS = (0.5, 1.0)
#: The inks the calibration was fitted on (active, passive).
CALIBRATED_MATERIALS = ("lce", "acrylate")


@dataclass(frozen=True)
class CalibratedRange:
    """Where the calibration's measurements lie.

    Attributes
    ----------
    speed
        Print speeds (mm/s) of the Janus-curvature series (ω* = 0).
    rotation_number
        Largest |ω*| of the L/L0 series (printed at ``rotation_speed``); ω* = 0 is the Janus
        series.
    rotation_speed
        Print speed (mm/s) of the L/L0 series.
    temperature
        Heating temperature of all series (°C).
    radius
        Filament radius (mm).
    materials
        The (active, passive) inks the calibration is for.
    """

    speed: tuple[float, float]
    rotation_number: float
    rotation_speed: float
    temperature: float
    radius: float
    materials: tuple[str, str] = CALIBRATED_MATERIALS

    def record(self) -> dict[str, Any]:
        """JSON-able form."""
        return {
            "speed_mm_s": list(self.speed),
            "rotation_number_abs": [0.0, self.rotation_number],
            "rotation_series_speed_mm_s": self.rotation_speed,
            "temperature_C": self.temperature,
            "radius_mm": self.radius,
            "active_fraction": list(CALIBRATED_FRACTIONS),
        }

    def text(self) -> str:
        """One phrase: ``v = 0.25-3 mm/s, |ω*| <= 2, 175 °C``."""
        lo, hi = self.speed
        return (
            f"v = {lo:g}-{hi:g} mm/s, |ω*| <= {self.rotation_number:g}, "
            f"{self.temperature:g} °C, R = {self.radius:g} mm"
        )

    def outside(
        self,
        *,
        speed: FloatArray | float | None = None,
        rotation_number: FloatArray | float | None = None,
        temperature: float | None = None,
        radius: float | None = None,
        active_fraction: float | None = None,
        materials: tuple[str, str] | None = None,
    ) -> list[str]:
        """Why these settings lie outside the calibrated range (empty list: inside)."""
        out = []
        tol = 1e-9
        if speed is not None:
            v = np.atleast_1d(np.asarray(speed, dtype=float))
            lo, hi = self.speed
            if v.min() < lo * (1 - tol) or v.max() > hi * (1 + tol):
                out.append(
                    f"speed {_span(v)} mm/s outside the calibrated {lo:g}-{hi:g} mm/s "
                    "(extrapolated)"
                )
        if rotation_number is not None:
            w = np.abs(np.atleast_1d(np.asarray(rotation_number, dtype=float)))
            if w.max() > self.rotation_number * (1 + tol):
                out.append(
                    f"|ω*| {_span(w)} outside the calibrated 0-{self.rotation_number:g} "
                    "(extrapolated)"
                )
        if temperature is not None and abs(temperature - self.temperature) > 1e-9:
            out.append(
                f"temperature {temperature:g} °C: the calibration is at {self.temperature:g} °C "
                "(the actuation at other temperatures is the model's assumption)"
            )
        if radius is not None and abs(radius - self.radius) > 1e-9:
            out.append(f"radius {radius:g} mm: the calibration is at R = {self.radius:g} mm")
        if active_fraction is not None and not any(
            abs(active_fraction - f) < 1e-9 for f in CALIBRATED_FRACTIONS
        ):
            out.append(
                f"active fraction {active_fraction:g}: the calibration has 0.5 (Janus) and 1 "
                "(pure LCE)"
            )
        if materials is not None and tuple(materials) != self.materials:
            out.append(
                f"materials {materials[0]}/{materials[1]}: the calibration is for "
                f"{self.materials[0]}/{self.materials[1]} (its band does not apply)"
            )
        return out


def _span(x: FloatArray) -> str:
    lo, hi = float(np.min(x)), float(np.max(x))
    return f"{lo:.4g}" if math.isclose(lo, hi) else f"{lo:.4g}-{hi:.4g}"


@lru_cache(maxsize=1)
def calibrated_range() -> CalibratedRange:
    """The calibrated range, read from the measured tables the calibration fits."""
    speeds = load_table("janus_curvature").x
    omegas = np.concatenate([load_table(g).x for g in ("pure_lce_length", "composite_length")])
    return CalibratedRange(
        speed=(float(speeds.min()), float(speeds.max())),
        rotation_number=float(np.abs(omegas).max()),
        rotation_speed=ROTATION_SERIES_SPEED,
        temperature=CALIBRATION_TEMPERATURE,
        radius=PAPER_RADIUS,
    )
