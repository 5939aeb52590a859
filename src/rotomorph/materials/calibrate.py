"""Predict the paper's measured filament quantities and calibrate model parameters to them.

Predictors (:func:`predict`, keyed by :class:`~rotomorph.materials.measurements.MeasuredTable`
name; straight filaments, full actuation, R = 0.3 mm, inks ``"lce"`` / ``"acrylate"``):

* ``janus_curvature``: K_J (1/mm) of a half-and-half filament printed at speed x (mm/s), ω* = 0;
* ``pure_lce_length``: L/L0 of a pure LCE filament at ω* = x, v = 3 mm/s; the uniform section has
  no natural curvature, so L/L0 = axial stretch (twisted rod);
* ``composite_length``: L/L0 of the free Janus helix (notes 1.6) at ω* = x, v = 3 mm/s, with
  K = |κ̄| and τ = ω*/R + Δτ.

:func:`calibrate` fits named float parameters of a
:class:`~rotomorph.materials.natural.FilamentModel` (dotted names reach into the strain model,
e.g. ``"strain_model.gain"``) by weighted least squares (``scipy.optimize.least_squares``,
weights 1/spread²). Standard uncertainties come from the Jacobian, cov = (JᵀJ)⁻¹ of the
weighted residuals with absolute sigma (the spreads are taken as known standard deviations; no
rescaling by χ², which is undefined with as many points as parameters).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.material import Material, get_material
from rotomorph.materials.measurements import MeasuredTable
from rotomorph.materials.morphology import HelixShape, free_helix
from rotomorph.materials.natural import FilamentModel

#: Print speed of the paper's rotated filaments (Fig. 2F/G), mm/s.
ROTATION_SERIES_SPEED = 3.0
#: Filament radius (mm): diameter ~600 µm (paper).
PAPER_RADIUS = 0.3


def _inks() -> tuple[Material, Material]:
    return get_material("lce"), get_material("acrylate")


def janus_curvature(
    model: FilamentModel, speed: FloatArray, radius: float = PAPER_RADIUS
) -> FloatArray:
    """Natural curvature K_J (1/mm, toward the active side) of a Janus filament at ω* = 0.

    Parameters
    ----------
    model
        Modelling choices.
    speed
        Print speeds v (mm/s).
    radius
        Filament radius R (mm).
    """
    active, passive = _inks()
    section = model.section(active, passive, radius, 0.5)
    e_par, e_perp, eps_p = model.strains(np.asarray(speed, dtype=float), passive)
    _, kappa, _ = section.natural_strains(0.0, e_par, e_perp, eps_p)
    return kappa[:, 0]


def filament_shapes(
    model: FilamentModel,
    omega_star: FloatArray,
    active_fraction: float,
    speed: float = ROTATION_SERIES_SPEED,
    radius: float = PAPER_RADIUS,
) -> list[HelixShape]:
    """Closed-form free shapes (notes 1.6) of straight filaments printed at rotation rates ω*.

    Parameters
    ----------
    model
        Modelling choices.
    omega_star
        Dimensionless rotation rates ω* = Rω/v.
    active_fraction
        0.5 (Janus composite) or 1.0 (pure LCE).
    speed
        Print speed v (mm/s).
    radius
        Filament radius R (mm).
    """
    active, passive = _inks()
    section = model.section(active, passive, radius, active_fraction)
    w = np.atleast_1d(np.asarray(omega_star, dtype=float))
    e_par, e_perp, eps_p = model.strains(np.full(len(w), speed), passive)
    eps_c, kappa, dtau = section.natural_strains(w, e_par, e_perp, eps_p)
    measure = model.strain_model.measure
    return [
        free_helix(float(np.hypot(*k)), float(wi / radius + dt), float(e), measure=measure)
        for wi, k, dt, e in zip(w, kappa, dtau, eps_c, strict=True)
    ]


def predict(quantity: str, x: FloatArray, model: FilamentModel) -> FloatArray:
    """Model prediction of a measured quantity (see module docstring) at control values x."""
    x = np.asarray(x, dtype=float)
    if quantity == "janus_curvature":
        return janus_curvature(model, x)
    if quantity == "pure_lce_length":
        return np.array([s.end_to_end_ratio for s in filament_shapes(model, x, 1.0)])
    if quantity == "composite_length":
        return np.array([s.end_to_end_ratio for s in filament_shapes(model, x, 0.5)])
    raise InvalidParameterError(
        "quantity",
        f"no predictor for {quantity!r}; available: janus_curvature, pure_lce_length, "
        "composite_length",
    )


def get_parameter(model: object, name: str) -> float:
    """Value of a dotted float parameter, e.g. ``"strain_model.gain"``."""
    obj = model
    for part in name.split("."):
        if not hasattr(obj, part):
            raise InvalidParameterError("params", f"{type(obj).__name__} has no parameter {part!r}")
        obj = getattr(obj, part)
    if obj is None:
        raise InvalidParameterError("params", f"{name} is None; give it a starting value first")
    return float(obj)  # type: ignore[arg-type]


def set_parameter(model: object, name: str, value: float) -> object:
    """Copy of a (nested) frozen dataclass with the dotted parameter ``name`` set to ``value``."""
    head, _, rest = name.partition(".")
    if not dataclasses.is_dataclass(model) or not hasattr(model, head):
        raise InvalidParameterError("params", f"{type(model).__name__} has no parameter {head!r}")
    new = set_parameter(getattr(model, head), rest, value) if rest else float(value)
    return dataclasses.replace(model, **{head: new})  # type: ignore[type-var]


@dataclass(frozen=True)
class ResidualRow:
    """One measured point with its prediction: ``x`` (control value), ``measured``, ``spread``,
    ``predicted`` (value units), ``normalized`` = (predicted − measured)/spread, ``used``
    (whether the point was fitted)."""

    condition: str
    x: float
    measured: float
    spread: float
    predicted: float
    normalized: float
    used: bool


@dataclass(frozen=True, eq=False)
class CalibrationResult:
    """Outcome of :func:`calibrate`.

    Attributes
    ----------
    model
        The model with fitted parameters.
    values, uncertainties
        Fitted values and standard uncertainties by parameter name.
    covariance
        ``(p, p)`` covariance matrix in ``params`` order.
    residuals
        One :class:`ResidualRow` per row of the table (fitted and predicted rows).
    cost
        ½ Σ normalized² over the fitted rows.
    success
        ``scipy.optimize.least_squares`` convergence flag.
    """

    model: FilamentModel
    values: dict[str, float]
    uncertainties: dict[str, float]
    covariance: FloatArray
    residuals: tuple[ResidualRow, ...]
    cost: float
    success: bool


def calibrate(
    data: MeasuredTable,
    params: Sequence[str],
    model: FilamentModel | None = None,
    *,
    use: Sequence[int] | None = None,
    bounds: tuple[Sequence[float], Sequence[float]] | None = None,
) -> CalibrationResult:
    """Fit model parameters to a measured table by weighted least squares.

    Parameters
    ----------
    data
        Measured table with a predictor (``janus_curvature``, ``pure_lce_length``,
        ``composite_length``).
    params
        Dotted names of float parameters of ``model`` to fit (e.g. ``["modulus_ratio"]``).
    model
        Starting model (its current values are the initial guesses); default FilamentModel().
    use
        Row indices used for the fit (default: all); the other rows are predicted only.
    bounds
        (lower, upper) per parameter; default (1e-6, inf) for each.

    Returns
    -------
    CalibrationResult

    Raises
    ------
    InvalidParameterError
        No parameters, more parameters than fitted points, zero spreads, unknown names.
    """
    model = FilamentModel() if model is None else model
    names = list(params)
    rows = np.arange(len(data)) if use is None else np.asarray(use, dtype=int)
    if not names:
        raise InvalidParameterError("calibrate.params", "name at least one parameter to fit")
    if len(rows) < len(names):
        raise InvalidParameterError(
            "calibrate.use", f"{len(rows)} points cannot determine {len(names)} parameters"
        )
    if np.any(data.spread[rows] <= 0.0):
        raise InvalidParameterError("calibrate.data", "spreads must be > 0 to weight the fit")
    x0 = np.array([get_parameter(model, n) for n in names])
    lo, hi = bounds if bounds is not None else ([1e-6] * len(names), [np.inf] * len(names))

    def with_values(p: FloatArray) -> FilamentModel:
        m: object = model
        for n, v in zip(names, p, strict=True):
            m = set_parameter(m, n, float(v))
        return m  # type: ignore[return-value]

    def residual(p: FloatArray) -> FloatArray:
        pred = predict(data.name, data.x[rows], with_values(p))
        return (pred - data.value[rows]) / data.spread[rows]

    sol = least_squares(residual, x0, bounds=(lo, hi), x_scale="jac", xtol=1e-12, ftol=1e-12)
    cov = np.linalg.pinv(sol.jac.T @ sol.jac)
    fitted = with_values(sol.x)
    pred_all = predict(data.name, data.x, fitted)
    used = np.zeros(len(data), dtype=bool)
    used[rows] = True
    table = tuple(
        ResidualRow(
            data.condition[i],
            float(data.x[i]),
            float(data.value[i]),
            float(data.spread[i]),
            float(pred_all[i]),
            float((pred_all[i] - data.value[i]) / data.spread[i]) if data.spread[i] > 0 else np.nan,
            bool(used[i]),
        )
        for i in range(len(data))
    )
    return CalibrationResult(
        model=fitted,
        values={n: float(v) for n, v in zip(names, sol.x, strict=True)},
        uncertainties={n: float(np.sqrt(cov[i, i])) for i, n in enumerate(names)},
        covariance=cov,
        residuals=table,
        cost=float(sol.cost),
        success=bool(sol.success),
    )


def paper_calibration() -> tuple[CalibrationResult, CalibrationResult]:
    """The filament model calibrated on the paper's Janus curvature data (Fig. 2D).

    First ``E_a/E_p`` at actuation temperature is fitted to ``K_J(v = 3 mm/s)`` with
    Warner–Terentjev strains (physics notes §1.7: the room-temperature ratio 52 under-predicts
    the curvature 2–4×); then, with that ratio held, the empirical threshold law's gain and
    threshold are fitted to ``v = 0.25`` and ``3 mm/s``. The other two speeds are predictions.

    Returns
    -------
    warner_terentjev, empirical_threshold
        The two calibration results; ``.model`` of the second is the default paper model.
    """
    from rotomorph.materials.measurements import load_table
    from rotomorph.materials.process import EmpiricalThreshold

    curv = load_table("janus_curvature")
    wt = calibrate(curv, ["modulus_ratio"], FilamentModel(), use=[curv.near(3.0)])
    emp = calibrate(
        curv,
        ["strain_model.gain", "strain_model.threshold"],
        FilamentModel(strain_model=EmpiricalThreshold(), modulus_ratio=wt.model.modulus_ratio),
        use=[curv.near(0.25), curv.near(3.0)],
    )
    return wt, emp
