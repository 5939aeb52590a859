"""Predict the paper's measured filament quantities and calibrate model parameters to them.

Predictors (:func:`predict`, keyed by :class:`~rotomorph.materials.measurements.MeasuredTable`
name; straight filaments, full actuation, R = 0.3 mm, inks ``"lce"`` / ``"acrylate"``):

* ``janus_curvature``: K_J (1/mm) of a half-and-half filament printed at speed x (mm/s), ω* = 0:
  the curvature of the heated filament per unit current length (what the paper measured on
  images of heated filaments);
* ``pure_lce_length``: L/L0 of a pure LCE filament at ω* = x, v = 3 mm/s; the uniform section has
  no natural curvature, so L/L0 = axial stretch (twisted rod);
* ``composite_length``: L/L0 of the free Janus helix at ω* = x, v = 3 mm/s, with
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
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import least_squares

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.inference import (
    Group,
    JointCalibration,
    Parameter,
    get_parameter,
    joint_calibrate,
    set_parameter,
)
from rotomorph.materials.material import Material, get_material
from rotomorph.materials.measurements import MeasuredTable, load_table
from rotomorph.materials.morphology import HelixShape, free_helix
from rotomorph.materials.natural import DIRECTOR_HELIX_SENSE, FilamentModel
from rotomorph.materials.process import EmpiricalThreshold, strain_to_stretch

#: Print speed of the paper's rotated filaments (Fig. 2F/G), mm/s.
ROTATION_SERIES_SPEED = 3.0
#: Filament radius (mm): diameter ~600 µm (paper).
PAPER_RADIUS = 0.3


def _inks() -> tuple[Material, Material]:
    return get_material("lce"), get_material("acrylate")


def _state(
    model: FilamentModel,
    speed: FloatArray,
    inks: tuple[Material, Material] | None,
    radius: float,
    fraction: float,
    temperature: float | None,
) -> tuple[Any, FloatArray, FloatArray, Any]:
    """Section and free strains of the pair at full actuation (``temperature`` None, the
    paper calibration) or at ``temperature`` (°C, as ``simulate`` evaluates them)."""
    active, passive = _inks() if inks is None else inks
    section = model.section(active, passive, radius, fraction, temperature)
    v = np.asarray(speed, dtype=float)
    if temperature is None:
        e_par, e_perp, eps_p = model.strains(v, passive)
    else:
        e_par, e_perp, eps_p = model.strains_at(v, active, passive, temperature)
    return section, e_par, e_perp, eps_p


def janus_curvature(
    model: FilamentModel,
    speed: FloatArray,
    radius: float = PAPER_RADIUS,
    *,
    inks: tuple[Material, Material] | None = None,
    active_fraction: float = 0.5,
    temperature: float | None = None,
) -> FloatArray:
    """Curvature K_J (1/mm, toward the active side) of a heated Janus filament at ω* = 0.

    The paper's Fig. 2D quantity, "the maximum curvature of the actuated filament", measured on
    images of filaments heated in the bath: the curvature of the heated centre line per unit of
    its *current* length, K/λ, where K is the natural curvature per printed length (a turning
    angle per printed length, :mod:`rotomorph.materials.natural`) and λ the natural stretch of
    the centre line. It is the curvature of :func:`filament_shapes` at ω* = 0 (a ring), of
    :func:`rotomorph.predict` and of the rod solver's heated shape.

    Parameters
    ----------
    model
        Modelling choices.
    speed
        Print speeds v (mm/s).
    radius
        Filament radius R (mm).
    inks
        (active, passive) materials; default the paper's.
    active_fraction
        Active share of the section.
    temperature
        ``None``: full actuation (the paper calibration); else at that temperature (°C).
    """
    section, e_par, e_perp, eps_p = _state(model, speed, inks, radius, active_fraction, temperature)
    eps_c, kappa, _ = section.natural_strains(0.0, e_par, e_perp, eps_p)
    return kappa[:, 0] / strain_to_stretch(eps_c, model.strain_model.measure)


def filament_shapes(
    model: FilamentModel,
    omega_star: FloatArray,
    active_fraction: float,
    speed: float | FloatArray = ROTATION_SERIES_SPEED,
    radius: float = PAPER_RADIUS,
    *,
    inks: tuple[Material, Material] | None = None,
    temperature: float | None = None,
) -> list[HelixShape]:
    """Closed-form free shapes of straight filaments printed at rotation rates ω*.

    Parameters
    ----------
    model
        Modelling choices.
    omega_star
        Dimensionless rotation rates ω* = Rω/v.
    active_fraction
        0.5 (Janus composite) or 1.0 (pure LCE).
    speed
        Print speed v (mm/s), one or one per ω*.
    radius
        Filament radius R (mm).
    inks
        (active, passive) materials; default the paper's.
    temperature
        ``None``: full actuation (the paper calibration); else at that temperature (°C).
    """
    # the director helix turns with DIRECTOR_HELIX_SENSE * omega* in the filament frame (the
    # design layer's alpha = psi - alpha_n), so the helix has the handedness the rod solver gives
    # the same print program
    w = DIRECTOR_HELIX_SENSE * np.atleast_1d(np.asarray(omega_star, dtype=float))
    v = np.broadcast_to(np.asarray(speed, dtype=float), w.shape)
    section, e_par, e_perp, eps_p = _state(model, v, inks, radius, active_fraction, temperature)
    eps_c, kappa, dtau = section.natural_strains(model.director_pitch * w, e_par, e_perp, eps_p)
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


# ----------------------------------------------------------------------------- paper recipe

#: Groups of the paper's measurements that the joint calibration fits (closed-form predictors);
#: every other group (sinusoids, lattices) is only ever predicted.
CALIBRATION_GROUPS = ("janus_curvature", "pure_lce_length", "composite_length")

#: Measured normalized length of pure passive filaments at 150 °C (paper, Fig. 1E).
PASSIVE_LENGTH, PASSIVE_LENGTH_SD = 1.03, 0.02

PREFERRED_BRANCH_REASON = (
    "E_a > E_p at actuation: the paper reports larger bending when the passive ink is blended "
    "with a stiffer one (Supp. Fig. 7), which lowers E_a/E_p; a bilayer bends more as the ratio "
    "approaches 1, so this is consistent with E_a/E_p > 1 only (reading of the paper's "
    "'modulus ratio' as E_p/E_a, the quantity the blends raise)"
)


def paper_parameters() -> tuple[Parameter, ...]:
    """The fitted parameters of the paper calibration with their (weak, stated) priors.

    * ``modulus_ratio`` E_a/E_p at actuation: ln-normal, centred on 1, one decade wide,
      symmetric so that it prefers neither branch. The 25 °C ratio 52 is not a prior: it
      under-predicts the Janus curvature 2–4× and the LCE at 25 °C is 28 K above its T_g.
    * ``strain_model.gain`` dε∥/dS of the threshold law: 2 ± 2 (order one; the ideal nematic
      rubber gives |dε∥/dQ| ≈ 0.9 at Q = 0.23).
    * ``strain_model.threshold`` S0: 0.115 ± 0.07, i.e. between 0 and S(3 mm/s) = 0.23
      (filaments printed at 3 mm/s contract).
    * ``passive_strain``: ln 1.03 ± 0.02/1.03, the measured free length of the passive ink
      (a measurement used as a prior, hence an input, not a prediction).
    """
    return (
        Parameter(
            "modulus_ratio",
            0.0,
            float(np.log(10.0)),
            log=True,
            lower=float(np.log(0.01)),
            upper=float(np.log(100.0)),
            reason="E_a/E_p at actuation not measured; ln-normal around 1, one decade, symmetric",
        ),
        Parameter(
            "strain_model.gain",
            2.0,
            2.0,
            lower=1e-3,
            upper=20.0,
            reason="order one (ideal nematic rubber: |d eps_par/dQ| = 0.9 at Q = 0.23)",
        ),
        Parameter(
            "strain_model.threshold",
            0.115,
            0.07,
            lower=-0.2,
            upper=0.229,
            reason="0 <= S0 < S(3 mm/s) = 0.23: filaments printed at 3 mm/s contract",
        ),
        Parameter(
            "passive_strain",
            float(np.log(PASSIVE_LENGTH)),
            PASSIVE_LENGTH_SD / PASSIVE_LENGTH,
            lower=-0.2,
            upper=0.2,
            reason="measured: pure passive filaments 1.03 +- 0.02 at 150 C (Fig. 1E), Hencky",
        ),
    )


def paper_base_model(resolution: int | None = None) -> FilamentModel:
    """Starting model of the paper calibration: threshold strain law, Hencky strains."""
    base = FilamentModel(
        strain_model=EmpiricalThreshold(),
        modulus_ratio=1.0,
        passive_strain=float(np.log(PASSIVE_LENGTH)),
    )
    return base if resolution is None else dataclasses.replace(base, resolution=resolution)


def paper_groups(names: Sequence[str] = CALIBRATION_GROUPS) -> tuple[Group, ...]:
    """The closed-form measured groups (tables with a :func:`predict` predictor)."""
    out = []
    for name in names:
        table = load_table(name)
        out.append(Group(name, table, _table_predictor(table)))
    return tuple(out)


def _table_predictor(table: MeasuredTable) -> Callable[[FilamentModel], FloatArray]:
    def run(model: FilamentModel) -> FloatArray:
        return predict(table.name, table.x, model)

    return run


#: Section-mesh resolution of the fit (boundary vertices): fitted values agree with 96 to 1e-4
#: relative, far below the data's spreads, at a third of the cost; predictions use finer meshes.
FIT_RESOLUTION = 64


def paper_calibration(
    exclude: Sequence[str] = (), *, resolution: int = FIT_RESOLUTION
) -> JointCalibration:
    """The filament model calibrated jointly on the paper's filament measurements.

    Fits E_a/E_p at actuation, the threshold strain law's gain and S0 and the passive strain
    (:func:`paper_parameters`) to the Janus curvature vs speed, the pure-LCE and the composite
    L/L0 vs ω* (:data:`CALIBRATION_GROUPS`), minus ``exclude`` (leave-one-group-out). Both
    modulus-ratio branches are fitted and reported; E_a > E_p is chosen when the data cannot
    tell (:data:`PREFERRED_BRANCH_REASON`).

    Parameters
    ----------
    exclude
        Group names left out of the fit.
    resolution
        Section-mesh resolution (boundary vertices) of the fit.
    """
    unknown = set(exclude) - set(CALIBRATION_GROUPS)
    if unknown:
        raise InvalidParameterError(
            "paper_calibration.exclude",
            f"unknown groups {sorted(unknown)}; choose from {', '.join(CALIBRATION_GROUPS)}",
        )
    groups = paper_groups([g for g in CALIBRATION_GROUPS if g not in exclude])
    return joint_calibrate(
        groups,
        paper_parameters(),
        paper_base_model(resolution),
        branch="modulus_ratio",
        preferred="above",
        preference_reason=PREFERRED_BRANCH_REASON,
    )
