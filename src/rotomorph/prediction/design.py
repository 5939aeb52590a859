"""A design file's quick prediction: its filaments, or its lattice's independent-edge estimate."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from rotomorph.prediction.band import CALIBRATION_TEMPERATURE, calibrated_range, calibration_of
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
    materials, range_record
        The design's materials file (name, version, sha256) and its calibrated range, when it
        names one (``None``: the paper's inks).
    """

    name: str
    temperature: float
    filaments: tuple[FilamentPrediction, ...]
    lattice: LatticePrediction | None
    materials: dict[str, Any] | None = None
    range_record: dict[str, Any] | None = None

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
            "band": _PAPER_BAND if self.materials is None else self.materials["band"],
            "calibrated_range": self.range_record or calibrated_range().record(),
            "materials": self.materials,
            "extrapolated": self.extrapolated,
            "filaments": [f.record() for f in self.filaments],
            "lattice": None if self.lattice is None else self.lattice.record(),
        }

    def lines(self) -> list[str]:
        """Lines for a terminal (first, with a materials file, which file and which band)."""
        out = []
        if self.materials is not None:
            m = self.materials
            out.append(
                f"materials '{m['name']}' version {m['version']} (sha256 {m['sha256'][:12]}): "
                f"± is {m['band']}"
            )
        out += [f.line() for f in self.filaments]
        if self.lattice is not None:
            out.append(self.lattice.line())
        return out


_PAPER_BAND = (
    "calibration only (posterior of the joint filament calibration, as the paper report); "
    "inputs the paper does not give are not in it"
)


def _file_band(inks: Any) -> str:
    """What a materials file's band is: its stored calibration covariance, or none."""
    cal = inks.document.calibration
    if cal is None or not cal.parameters:
        return "none: the materials file stores no calibration covariance (values without a band)"
    fitted = ", ".join(cal.parameters)
    return (
        f"calibration only (the posterior covariance of {fitted} stored in the file by its "
        f"calibration, data sha256 {cal.data_sha256[:12]}); inputs the file does not fit are "
        "not in it"
    )


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
    inks = design.material_set  # a design's own materials file: its pairs' models and bands
    filaments = []
    for i, f in enumerate(design.filaments):
        with calibration_of(inks, f.active_material, f.passive_material):
            name = f.name or f"filaments[{i}]"
            filaments.append(predict_filament(f.to_program(), name, temperature=temperature))
    lattice = None
    if design.lattice is not None:
        lat = design.lattice
        with calibration_of(inks, lat.active_material, lat.passive_material):
            lattice = predict_lattice(lat, temperature=temperature)
    if inks is None:
        return DesignPrediction(design.name, float(temperature), tuple(filaments), lattice)
    with calibration_of(inks, inks.names("active")[0], inks.names("passive")[0]):
        rng = calibrated_range().record()
    record = {**inks.record(), "band": _file_band(inks)}
    return DesignPrediction(design.name, float(temperature), tuple(filaments), lattice, record, rng)
