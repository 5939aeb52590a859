"""The calibration behind every quick prediction: nominal model, ± band, calibrated range.

A prediction here is the paper report's: the model calibrated jointly on all of the paper's
filament measurements (:func:`rotomorph.materials.calibrate.paper_calibration`, the chosen
branch), evaluated on the report's section mesh
(:func:`rotomorph.simulate.validation.at_resolution`), with the calibration's uncertainty
propagated by :meth:`rotomorph.materials.inference.Fit.propagate`
(secants over ± one posterior standard deviation along each independent direction of the
posterior covariance, on the fit's mesh). The band is the calibration's only: inputs the paper
does not give (cell size, filament width, …) are not in it.

The calibrated range is where the measurements lie (:func:`calibrated_range`): print speeds of
the Janus-curvature series (at ω* = 0) and rotation numbers of the L/L0 series (at 3 mm/s),
all heated to 175 °C, filaments of radius 0.3 mm with half (composite) or all (pure LCE) of the
section active. A setting outside it is an extrapolation of the fitted laws and is flagged as
one wherever it is reported.

A design that names its own materials file is predicted with that file's inks and model:
:func:`calibration_of` makes the nominal model, the band (the file's stored posterior
covariance; none when the file stores none) and the calibrated range those of the file's pair
while a prediction runs.
"""

from __future__ import annotations

import contextlib
import math
from collections.abc import Callable, Iterator
from contextvars import ContextVar
from dataclasses import dataclass, replace
from functools import lru_cache
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.calibrate import ROTATION_SERIES_SPEED
from rotomorph.materials.calibrated_range import (
    CALIBRATED_FRACTIONS,
    CALIBRATED_MATERIALS,
    CALIBRATION_TEMPERATURE,
    CalibratedRange,
)
from rotomorph.materials.calibrated_range import calibrated_range as _paper_range
from rotomorph.materials.inference import Fit
from rotomorph.materials.natural import FilamentModel

__all__ = [
    "CALIBRATED_FRACTIONS",
    "CALIBRATED_MATERIALS",
    "CALIBRATION_TEMPERATURE",
    "CalibratedRange",
    "Estimate",
    "calibrated_inks",
    "calibrated_materials",
    "calibrated_range",
    "calibrated_set",
    "calibration_fit",
    "calibration_of",
    "nominal_model",
    "nominal_only",
    "with_band",
]


@dataclass(frozen=True, eq=False)
class _FileCalibration:
    """A materials file's pair, while :func:`calibration_of` holds it."""

    materials: Any
    names: tuple[str, str]
    fit: Fit | None
    nominal: FilamentModel
    range: CalibratedRange


_FILE: ContextVar[_FileCalibration | None] = ContextVar("rotomorph_prediction_file", default=None)


_NOMINAL_ONLY: ContextVar[bool] = ContextVar("rotomorph_prediction_nominal_only", default=False)


@contextlib.contextmanager
def nominal_only() -> Iterator[None]:
    """While held, :func:`with_band` gives nominal values only (every ``sd`` ``None``).

    The band costs one evaluation of the quantity per independent direction of the
    calibration's posterior on top of the nominal one; a page that shows the nominal value at
    once and its band a moment later predicts first inside this.
    """
    token = _NOMINAL_ONLY.set(True)
    try:
        yield
    finally:
        _NOMINAL_ONLY.reset(token)


def _file_range(materials: Any) -> CalibratedRange:
    """Where a materials file's calibration was measured: its order parameter's speeds, the
    nozzle's radius, its actuation temperature (the file stores no ω* range: the paper's)."""
    doc = materials.document
    active = next(iter(materials.names("active")), None)
    speeds = [1.0] if active is None else [v for v, _ in materials.order_points(active)]
    return CalibratedRange(
        speed=(float(min(speeds)), float(max(speeds))),
        rotation_number=_paper_range().rotation_number,
        rotation_speed=ROTATION_SERIES_SPEED,
        temperature=float(doc.conditions.actuation_temperature.value),
        radius=float(doc.nozzle.filament_radius.value),
    )


@contextlib.contextmanager
def calibration_of(materials: Any, active: str, passive: str) -> Iterator[None]:
    """Predict with ``materials``' pair (a :class:`~rotomorph.materials.parameter_set.MaterialSet`)
    inside the block; ``materials = None``: the paper's calibration (no change)."""
    if materials is None:
        yield
        return
    from rotomorph.simulate.validation import at_resolution

    nominal = at_resolution(materials.filament_model(active, passive))
    state = _FileCalibration(
        materials,
        (active, passive),
        materials.calibration_fit(active, passive),
        nominal,
        replace(_file_range(materials), materials=(active, passive)),
    )
    token = _FILE.set(state)
    try:
        yield
    finally:
        _FILE.reset(token)


def calibrated_materials() -> tuple[str, str]:
    """The (active, passive) inks the current calibration is for."""
    state = _FILE.get()
    return CALIBRATED_MATERIALS if state is None else state.names


def calibrated_inks() -> tuple[Any, Any]:
    """The current calibration's two inks as :class:`~rotomorph.materials.material.Material` s."""
    state = _FILE.get()
    if state is None:
        from rotomorph.materials.material import get_material

        return get_material(CALIBRATED_MATERIALS[0]), get_material(CALIBRATED_MATERIALS[1])
    return state.materials.material(state.names[0]), state.materials.material(state.names[1])


def calibrated_set() -> Any:
    """The materials file of the current calibration (``None``: the paper's inks)."""
    state = _FILE.get()
    return None if state is None else state.materials


def calibrated_range() -> CalibratedRange:
    """The calibrated range of the current calibration (the paper's, or a materials file's)."""
    state = _FILE.get()
    return _paper_range() if state is None else state.range


def calibration_fit() -> Fit:
    """The current calibration's fit: the report's (below), or a materials file's stored
    posterior (:func:`calibration_of`; raises when the file stores none)."""
    state = _FILE.get()
    if state is None:
        return _paper_fit()
    if state.fit is None:
        raise InvalidParameterError(
            "materials",
            f"{state.materials.name!r} stores no calibration covariance: no band to propagate",
        )
    return state.fit


@lru_cache(maxsize=1)
def _paper_fit() -> Fit:
    """The chosen fit of the joint calibration on all filament groups (the report's).

    About half a second of CPU the first time; kept in the package's disk cache
    (:mod:`rotomorph.simulate.cache`), which any change of code or data invalidates.
    """
    from rotomorph.materials.calibrate import paper_calibration
    from rotomorph.simulate.cache import disk_cached

    return disk_cached("paper_calibration", "all groups", lambda: paper_calibration()).chosen


def nominal_model() -> FilamentModel:
    """The calibrated model on the report's section mesh (its Fig. 2 curves use this one);
    inside :func:`calibration_of`, the materials file's model of its pair."""
    from rotomorph.simulate.validation import at_resolution

    state = _FILE.get()
    if state is not None:
        return state.nominal
    return at_resolution(calibration_fit().model)


@dataclass(frozen=True)
class Estimate:
    """A predicted number with its calibration band.

    Attributes
    ----------
    value
        Nominal prediction.
    sd
        Calibration standard deviation (``None``: not propagated).
    unit
        Unit text (``"1/mm"``, ``"mm"``, ``"1"``).
    """

    value: float
    sd: float | None
    unit: str

    def text(self, digits: int = 3) -> str:
        """``0.619 ± 0.052 1/mm`` (``inf`` and ``nan`` as words)."""
        if not math.isfinite(self.value):
            return "none" if math.isnan(self.value) else "infinite"
        unit = "" if self.unit == "1" else f" {self.unit}"
        if self.sd is None or not math.isfinite(self.sd):
            return f"{self.value:.{digits}g}{unit}"
        return f"{self.value:.{digits}g} ± {self.sd:.2g}{unit}"

    def record(self) -> dict[str, Any]:
        """JSON-able form (non-finite numbers as ``null``)."""
        return {
            "value": _finite(self.value),
            "sd_calibration": None if self.sd is None else _finite(self.sd),
            "unit": self.unit,
        }


def _finite(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


def with_band(quantity: Callable[[FilamentModel], FloatArray], units: list[str]) -> list[Estimate]:
    """Nominal values of ``quantity(model)`` and their calibration sd (module docstring).

    ``quantity`` returns one number per entry of ``units``. The value is taken on the report's
    mesh (:func:`nominal_model`), the sensitivities on the fit's mesh, as the report does.
    """
    state = _FILE.get()
    value = np.asarray(quantity(nominal_model()), dtype=float)
    no_covariance = state is not None and state.fit is None  # a file that stores none
    if _NOMINAL_ONLY.get() or no_covariance:
        return [Estimate(float(v), None, u) for v, u in zip(value, units, strict=True)]
    fit = calibration_fit()
    with np.errstate(invalid="ignore"):
        _, sd = fit.propagate(quantity)
    return [
        Estimate(float(v), float(s) if math.isfinite(v) else None, u)
        for v, s, u in zip(value, sd, units, strict=True)
    ]
