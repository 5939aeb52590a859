"""A design file's quick prediction: its filaments, or its lattice's independent-edge estimate."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rotomorph.prediction.band import CALIBRATION_TEMPERATURE, calibrated_range
from rotomorph.prediction.filament import FilamentPrediction, predict_filament
from rotomorph.prediction.lattice import LatticePrediction, predict_lattice

__all__ = ["DesignPrediction", "predict_design"]


@dataclass(frozen=True)
class DesignPrediction:
    """What :func:`predict_design` found.

    Attributes
    ----------
    name
        The design's name.
    temperature
        Heating temperature (°C).
    filaments
        One prediction per filament (empty for a lattice).
    lattice
        The lattice's independent-edge estimate, or ``None``.
    """

    name: str
    temperature: float
    filaments: tuple[FilamentPrediction, ...]
    lattice: LatticePrediction | None

    @property
    def extrapolated(self) -> bool:
        """True when any setting lies outside the calibrated range."""
        parts: list[Any] = [*self.filaments, *([self.lattice] if self.lattice else [])]
        return any(p.extrapolated for p in parts)

    def record(self) -> dict[str, Any]:
        """JSON-able form (what ``rotomorph predict --json`` prints)."""
        return {
            "design": self.name,
            "temperature_C": self.temperature,
            "band": "calibration only (posterior of the joint filament calibration, as the "
            "paper report); inputs the paper does not give are not in it",
            "calibrated_range": calibrated_range().record(),
            "extrapolated": self.extrapolated,
            "filaments": [f.record() for f in self.filaments],
            "lattice": None if self.lattice is None else self.lattice.record(),
        }

    def lines(self) -> list[str]:
        """Lines for a terminal."""
        out = [f.line() for f in self.filaments]
        if self.lattice is not None:
            out.append(self.lattice.line())
        return out


def predict_design(
    design: Any, *, temperature: float = CALIBRATION_TEMPERATURE
) -> DesignPrediction:
    """Quick prediction of a :class:`~rotomorph.io.designfile.Design` heated to ``temperature``.

    Parameters
    ----------
    design
        A validated design.
    temperature
        Heating temperature (°C); the calibration's is 175 °C.
    """
    filaments = tuple(
        predict_filament(f.to_program(), f.name or f"filaments[{i}]", temperature=temperature)
        for i, f in enumerate(design.filaments)
    )
    lattice = None
    if design.lattice is not None:
        lattice = predict_lattice(design.lattice, temperature=temperature)
    return DesignPrediction(design.name, float(temperature), filaments, lattice)
