"""Calibrating a lab's own inks from its measurement tables (``rotomorph calibrate``).

The same inference as the paper's calibration (:mod:`rotomorph.materials.inference`: maximum a
posteriori with stated Gaussian priors, weights 1/sd², Laplace covariance, both branches of the
bilayer symmetry m ↔ 1/m, leave-one-group-out predictions), on the groups the tables hold
(:mod:`rotomorph.materials.lab_model`), with the model evaluated as ``simulate`` evaluates it.

Fitted (:func:`lab_parameters`): the modulus ratio E_a/E_p at actuation (ln-normal around 1,
one decade, both branches), the threshold strain law's gain and threshold S0, the passive free
strain, T_NI and the width of the transition. Used as measured (inputs): both inks' moduli at
the print temperature, the order parameter's points, and the glass transitions, densities and
Poisson ratios given. Before fitting, :func:`~rotomorph.materials.identifiability.identifiability`
says which parameters the tables determine; a table set that cannot determine the strain law or
the modulus ratio is refused (:class:`~rotomorph.errors.InvalidParameterError`, one line naming
the missing measurement). :func:`calibrate_tables` returns the fit, the identifiability before
and after it, the leave-one-group-out predictions and the :class:`MaterialSet` to write.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import PurePath
from typing import Any, Final

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.identifiability import Identifiability, identifiability
from rotomorph.materials.inference import Fit, Group, JointCalibration, Parameter, joint_calibrate
from rotomorph.materials.lab_model import InkPair, predictor
from rotomorph.materials.lab_tables import Measurement, MeasurementSet, table
from rotomorph.materials.material import Material
from rotomorph.materials.natural import FilamentModel
from rotomorph.materials.parameter_set import MaterialSet, materials_from_mapping
from rotomorph.materials.process import PAPER_ORDER_POINTS, EmpiricalThreshold, order_parameter

__all__ = [
    "ESSENTIAL",
    "HINTS",
    "LABELS",
    "CalibrationSettings",
    "LabCalibration",
    "calibrate_tables",
    "lab_parameters",
]

#: Section-mesh resolution of the fit (as the paper calibration's).
FIT_RESOLUTION: Final = 64

LABELS: Final = {
    "model.modulus_ratio": "E_a/E_p at actuation",
    "model.strain_model.gain": "strain-law gain",
    "model.strain_model.threshold": "strain-law threshold S0",
    "model.passive_strain": "passive free strain",
    "active.transition_temperature": "T_NI",
    "model.transition_width": "transition width",
}
HINTS: Final = {
    "model.modulus_ratio": "the tensile modulus of both inks at the actuation temperature "
    "(youngs_modulus rows at T_act), or composite coils (composite_length at small omega*)",
    "model.strain_model.gain": "janus_curvature at >= 2 print speeds",
    "model.strain_model.threshold": "janus_curvature at >= 2 print speeds whose order "
    "parameters differ",
    "model.passive_strain": "free_length of the passive ink at the actuation temperature",
    "active.transition_temperature": "free_length of the active ink (pure filaments, v given) "
    "at >= 3 temperatures through the transition",
    "model.transition_width": "free_length of the active ink at >= 3 temperatures through the "
    "transition",
}
#: Parameters without which the tables do not determine the printed shapes: refused.
ESSENTIAL: Final = ("model.strain_model.gain", "model.strain_model.threshold")
#: Keys of the materials file the fitted parameters are written to: (ink role, key).
FILE_KEYS: Final = {
    "model.modulus_ratio": ("active", "actuated_modulus_ratio"),
    "model.strain_model.gain": ("active", "strain_gain"),
    "model.strain_model.threshold": ("active", "strain_threshold"),
    "model.passive_strain": ("passive", "free_strain"),
    "active.transition_temperature": ("active", "transition_temperature"),
    "model.transition_width": ("active", "transition_width"),
}
BRANCH_REASON: Final = (
    "E_a >= E_p at actuation assumed: no table distinguishes the two branches of the bilayer "
    "symmetry; measure both inks' moduli at the actuation temperature to decide"
)
GROUPS: Final = (
    ("janus_curvature", None),
    ("pure_lce_length", None),
    ("composite_length", None),
    ("free_length", "active"),
    ("free_length", "passive"),
    ("youngs_modulus", "active"),
    ("youngs_modulus", "passive"),
)


@dataclass(frozen=True)
class CalibrationSettings:
    """What the tables do not say (each default is recorded as assumed).

    Attributes
    ----------
    name
        Name of the materials file written.
    active, passive
        Ink names (default: those the tables name).
    print_temperature, actuation_temperature
        °C; ``None``: the defaults 25 and 175 °C, recorded as assumed.
    radius, active_fraction
        Filament radius (mm) and active share of the calibration prints; ``None``: 0.3 mm and
        0.5, recorded as assumed.
    resolution
        Section-mesh resolution of the fit.
    leave_one_out
        Refit without each group and predict it (the out-of-sample check).
    report
        Where the calibration report is written (relative to the materials file), recorded in
        the file.
    """

    name: str = "lab-inks"
    active: str | None = None
    passive: str | None = None
    print_temperature: float | None = None
    actuation_temperature: float | None = None
    radius: float | None = None
    active_fraction: float | None = None
    resolution: int = FIT_RESOLUTION
    leave_one_out: bool = True
    report: str = ""


@dataclass(frozen=True, eq=False)
class LabCalibration:
    """Outcome of :func:`calibrate_tables` (see module docstring)."""

    measurements: MeasurementSet
    settings: CalibrationSettings
    base: InkPair
    parameters: tuple[Parameter, ...]
    groups: tuple[Group, ...]
    joint: JointCalibration
    before: Identifiability
    after: Identifiability
    held_out: dict[str, tuple[FloatArray, FloatArray]]
    materials: MaterialSet
    inputs: dict[str, Any] = field(default_factory=dict)

    @property
    def fit(self) -> Fit:
        """The chosen branch's fit."""
        return self.joint.chosen

    def group_rows(self, name: str) -> tuple[Measurement, ...]:
        """The measurements of one fitted group."""
        return self.inputs["rows"][name]  # type: ignore[no-any-return]


def _weighted(rows: Sequence[Measurement]) -> tuple[float, float]:
    w = np.array([1.0 / m.spread**2 for m in rows])
    v = np.array([m.value for m in rows])
    return float(np.sum(w * v) / np.sum(w)), float(1.0 / math.sqrt(np.sum(w)))


def _cite(rows: Sequence[Measurement]) -> str:
    """``name.csv rows 3, 4 (source)``: the file's name (not its folder: the file written is
    the same wherever the tables were read from; the data hash identifies them)."""
    files: dict[str, list[int]] = {}
    for m in rows:
        files.setdefault(PurePath(m.file).name, []).append(m.row)
    parts = [
        f"{f} row{'s' if len(r) > 1 else ''} {', '.join(map(str, r))}" for f, r in files.items()
    ]
    first = rows[0].source if rows else ""
    return f"{'; '.join(parts)} ({first})" if first else "; ".join(parts)


def _provenance(rows: Sequence[Measurement]) -> str:
    """``cited`` when every row is cited from a publication, else ``measured``."""
    return "cited" if rows and all(m.provenance == "cited" for m in rows) else "measured"


def _value(value: float, unit: str, provenance: str, source: str, **extra: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"value": float(value), "unit": unit, "provenance": provenance}
    out["source"] = source
    out.update({k: v for k, v in extra.items() if v is not None})
    return out


def lab_parameters(
    order_points: tuple[tuple[float, float], ...],
    janus_speeds: Sequence[float],
    print_temperature: float,
    actuation_temperature: float,
) -> tuple[Parameter, ...]:
    """The fitted parameters of a lab calibration with their stated priors.

    * E_a/E_p at actuation: ln-normal around 1, one decade, symmetric (both branches);
    * gain: 2 ± 2 (order one; ideal nematic rubber gives |dε∥/dQ| ≈ 1);
    * threshold S0: between 0 and the order parameter at the fastest measured Janus speed
      (S_top/2 ± 0.3 S_top; the fastest filaments bend);
    * passive free strain: 0 ± 0.05 (thermal expansion of an elastomer over ~150 K);
    * T_NI: midway between the print and the actuation temperature, ± a quarter of the span;
    * transition width: ln-normal around 10 °C, a factor 3.
    """
    top = float(order_parameter(max(janus_speeds), order_points)) if janus_speeds else 0.3
    top = max(top, 0.02)
    span = actuation_temperature - print_temperature
    mid = 0.5 * (print_temperature + actuation_temperature)
    return (
        Parameter(
            "model.modulus_ratio",
            0.0,
            float(np.log(10.0)),
            log=True,
            lower=float(np.log(0.01)),
            upper=float(np.log(100.0)),
            reason="E_a/E_p at actuation: ln-normal around 1, one decade, symmetric",
        ),
        Parameter("model.strain_model.gain", 2.0, 2.0, lower=1e-3, upper=20.0, reason="order one"),
        Parameter(
            "model.strain_model.threshold",
            0.5 * top,
            0.3 * top,
            lower=-0.2,
            upper=top - 1e-3,
            reason=f"0 <= S0 < S at the fastest measured Janus speed ({top:.3g})",
        ),
        Parameter(
            "model.passive_strain",
            0.0,
            0.05,
            lower=-0.2,
            upper=0.2,
            reason="thermal expansion of an elastomer: a few per cent",
        ),
        Parameter(
            "active.transition_temperature",
            mid,
            0.25 * span,
            lower=print_temperature - span,
            upper=actuation_temperature + span,
            reason="between the print and the actuation temperature",
        ),
        Parameter(
            "model.transition_width",
            float(np.log(10.0)),
            float(np.log(3.0)),
            log=True,
            lower=float(np.log(0.5)),
            upper=float(np.log(100.0)),
            reason="ln-normal around 10 °C, a factor 3",
        ),
    )


def _names(data: MeasurementSet, settings: CalibrationSettings) -> tuple[str, str]:
    named = data.ink_names()
    out = []
    for role in ("active", "passive"):
        given = getattr(settings, role)
        if given is not None and role in named and named[role] != given:
            raise InvalidParameterError(
                f"--{role}", f"{given!r} but the tables name the {role} ink {named[role]!r}"
            )
        name = given or named.get(role)
        if name is None:
            raise InvalidParameterError(
                "MEASUREMENTS",
                f"missing measurement: no row names the {role} ink; add its youngs_modulus at "
                f"the print temperature (condition {role}=NAME)",
            )
        out.append(name)
    if out[0] == out[1]:
        raise InvalidParameterError("--passive", "the two inks need different names")
    return out[0], out[1]


def _ink_inputs(
    data: MeasurementSet, role: str, name: str, t_print: float
) -> dict[str, tuple[float, float | None, str, str]]:
    """(value, sd, provenance, source) of an ink's measured or assumed single values."""
    moduli = [m for m in data.of("youngs_modulus", role) if abs(m.x - t_print) <= 0.5]
    if not moduli:
        raise InvalidParameterError(
            "MEASUREMENTS",
            f"missing measurement: youngs_modulus of the {role} ink {name!r} at the print "
            f"temperature {t_print:g} °C (a tensile test; condition {role}={name})",
        )
    out: dict[str, tuple[float, float | None, str, str]] = {}
    e, sd = _weighted(moduli)
    out["youngs_modulus"] = (e, sd, _provenance(moduli), _cite(moduli))
    defaults = {
        "poisson_ratio": (0.5, "incompressible elastomer (no poisson_ratio table)"),
        "density": (1.1, "typical acrylate elastomer (no density table); only the weight uses it"),
    }
    for key in ("poisson_ratio", "density", "glass_transition"):
        rows = data.of(key, role)
        if rows:
            v, s = _weighted(rows)
            out[key] = (v, s, _provenance(rows), _cite(rows))
        elif key in defaults:
            out[key] = (defaults[key][0], None, "assumed", defaults[key][1])
    return out


def _groups(data: MeasurementSet, t_print: float) -> dict[str, tuple[Measurement, ...]]:
    out: dict[str, tuple[Measurement, ...]] = {}
    for quantity, role in GROUPS:
        rows = data.of(quantity, role)
        if quantity == "youngs_modulus":  # the print-temperature rows are inputs
            rows = tuple(m for m in rows if abs(m.x - t_print) > 0.5)
        if rows:
            out[quantity if role is None else f"{quantity}_{role}"] = rows
    return out


def _order_points(
    data: MeasurementSet,
) -> tuple[tuple[tuple[float, float], ...], tuple[float, ...] | None, str, str]:
    rows = data.of("order_parameter")
    if not rows:
        return (
            PAPER_ORDER_POINTS,
            None,
            "assumed",
            "no order_parameter table: the paper's WAXS points (Abdelrahman et al., Supp. "
            "Figs 8-9) are assumed; S is then only the coordinate of the strain law",
        )
    speeds = sorted({m.x for m in rows})
    points, sds = [], []
    for v in speeds:
        mean, sd = _weighted([m for m in rows if m.x == v])
        points.append((v, mean))
        sds.append(sd)
    return tuple(points), tuple(sds), _provenance(rows), _cite(rows)


def _refuse_degenerate(before: Identifiability, groups: dict[str, Any]) -> None:
    if not groups:
        raise InvalidParameterError(
            "MEASUREMENTS",
            "missing measurement: no table to fit (janus_curvature, pure_lce_length, "
            "composite_length, free_length, youngs_modulus at other temperatures)",
        )
    for p in before.parameters:
        if p.name in ESSENTIAL and p.status == "at its prior":
            raise InvalidParameterError(
                "MEASUREMENTS",
                f"missing measurement: the tables do not determine the {p.label} "
                f"(posterior/prior width {p.width_ratio:.2f}); add {p.pinned_by}",
            )


def calibrate_tables(
    data: MeasurementSet, settings: CalibrationSettings | None = None
) -> LabCalibration:
    """Calibrate the inks of ``data`` (see module docstring).

    Raises
    ------
    InvalidParameterError
        A missing measurement (one line naming it), inconsistent ink names.
    """
    settings = CalibrationSettings() if settings is None else settings
    active_name, passive_name = _names(data, settings)
    t_print = 25.0 if settings.print_temperature is None else float(settings.print_temperature)
    t_act = (
        175.0 if settings.actuation_temperature is None else float(settings.actuation_temperature)
    )
    if not t_print < t_act:
        raise InvalidParameterError(
            "--actuation-temperature", f"must exceed the print temperature {t_print:g} °C"
        )
    radius = 0.3 if settings.radius is None else float(settings.radius)
    fraction = 0.5 if settings.active_fraction is None else float(settings.active_fraction)
    a_in = _ink_inputs(data, "active", active_name, t_print)
    p_in = _ink_inputs(data, "passive", passive_name, t_print)
    points, point_sd, point_prov, point_src = _order_points(data)
    rows = _groups(data, t_print)
    janus = [m.x for m in rows.get("janus_curvature", ())]
    params = lab_parameters(points, janus, t_print, t_act)
    by = {p.name: p for p in params}
    model = FilamentModel(
        strain_model=EmpiricalThreshold(
            gain=by["model.strain_model.gain"].mean,
            threshold=by["model.strain_model.threshold"].mean,
            order_points=points,
        ),
        modulus_ratio=1.0,
        passive_strain=0.0,
        transition_width=10.0,
        print_temperature=t_print,
        actuation_temperature=t_act,
        resolution=settings.resolution,
    )

    def material(name: str, kind: str, inputs: dict[str, Any]) -> Material:
        tg = inputs.get("glass_transition")
        return Material(
            name=name,
            kind=kind,  # type: ignore[arg-type]
            youngs_modulus=inputs["youngs_modulus"][0],
            poisson_ratio=inputs["poisson_ratio"][0],
            glass_transition=None if tg is None else tg[0],
            transition_temperature=by["active.transition_temperature"].mean
            if kind == "active"
            else None,
            actuation_length=1.0,
            density=inputs["density"][0],
        )

    base = InkPair(
        model,
        material(active_name, "active", a_in),
        material(passive_name, "passive", p_in),
        radius,
        fraction,
    )
    groups = tuple(Group(name, table(name, r), predictor(r)) for name, r in rows.items())
    start = np.array([p.mean for p in params])
    start[0] = max(params[0].sd, 0.5)  # the preferred branch's start (E_a > E_p)
    before = identifiability(
        groups, params, base, start, labels=LABELS, hints=HINTS,
        where="prior mean, E_a/E_p = 10 (before fitting)",
    )  # fmt: skip
    _refuse_degenerate(before, rows)
    joint = joint_calibrate(
        groups,
        params,
        base,
        branch="model.modulus_ratio",
        preferred="above",
        preference_reason=BRANCH_REASON,
    )
    fit = joint.chosen
    after = identifiability(
        groups, params, base, fit.theta, labels=LABELS, hints=HINTS,
        where=f"the fitted optimum, branch {fit.label.replace('model.modulus_ratio', 'E_a/E_p')}",
    )  # fmt: skip
    held_out: dict[str, tuple[FloatArray, FloatArray]] = {}
    if settings.leave_one_out and len(groups) > 1:
        for g in groups:
            rest = [o for o in groups if o.name != g.name]
            other = joint_calibrate(
                rest, params, base, branch="model.modulus_ratio", preferred="above",
                preference_reason=BRANCH_REASON,
            ).chosen  # fmt: skip
            held_out[g.name] = other.propagate(g.predict)
    inputs = {
        "rows": rows,
        "active": a_in,
        "passive": p_in,
        "order_points": points,
        "order_sd": point_sd,
        "order_provenance": (point_prov, point_src),
        "names": (active_name, passive_name),
    }
    inks = _materials_set(data, settings, base, params, joint, after, inputs)
    return LabCalibration(
        data, settings, base, params, groups, joint, before, after, held_out, inks, inputs
    )


def _fitted_entries(
    params: Sequence[Parameter], fit: Fit, after: Identifiability, data: MeasurementSet
) -> dict[str, dict[str, Any]]:
    """File entries of the fitted parameters: calibrated, or assumed where at the prior."""
    sd = fit.sd_coordinate
    intervals = fit.intervals
    status = {p.name: p for p in after.parameters}
    out = {}
    for p in params:
        role, key = FILE_KEYS[p.name]
        value = fit.values[p.name]
        report = status[p.name]
        prior = (
            f"ln-normal, ln value ~ N({p.mean:.4g}, {p.sd:.3g})"
            if p.log
            else f"N({p.mean:.4g}, {p.sd:.3g})"
        )
        if report.status == "at its prior":
            provenance = "assumed"
            source = (
                f"stays at its prior {prior} (posterior/prior width {report.width_ratio:.2f}): "
                f"no table determines it; {report.pinned_by} would"
            )
        else:
            provenance = "calibrated"
            tables = ", ".join(t for t, s in report.informed_by if s >= 0.05)
            source = (
                f"rotomorph calibrate: maximum a posteriori of the joint fit (prior {prior}), "
                f"informed by {tables} (posterior/prior width {report.width_ratio:.2f}); data "
                f"sha256 {data.sha256[:16]}; a fit, not a measurement"
            )
        s = sd[p.name] * value if p.log else sd[p.name]
        entry = _value(value, "1", provenance, source, sd=float(s))
        if p.log:
            entry["interval"] = [float(v) for v in intervals[p.name]]
        out[f"{role}.{key}"] = entry
    return out


def _materials_set(
    data: MeasurementSet,
    settings: CalibrationSettings,
    base: InkPair,
    params: Sequence[Parameter],
    joint: JointCalibration,
    after: Identifiability,
    inputs: dict[str, Any],
) -> MaterialSet:
    fit = joint.chosen
    model = base.model
    active_name, passive_name = inputs["names"]
    fitted = _fitted_entries(params, fit, after, data)
    units = {
        "youngs_modulus": "MPa",
        "poisson_ratio": "1",
        "density": "g/cm3",
        "glass_transition": "C",
    }

    def singles(values: dict[str, Any]) -> dict[str, Any]:
        out = {}
        for key, (v, sd, prov, src) in values.items():
            extra = {"sd": sd}
            if key == "youngs_modulus":
                extra["temperature"] = model.print_temperature
            out[key] = _value(v, units[key], prov, src, **extra)
        return out

    def stated(given: float | None, default: float, unit: str, what: str) -> dict[str, Any]:
        if given is None:
            return _value(default, unit, "assumed", f"rotomorph calibrate's default {what}")
        return _value(given, unit, "measured", f"stated by the lab (rotomorph calibrate {what})")

    order_prov, order_src = inputs["order_provenance"]
    speeds = [v for v, _ in inputs["order_points"]]
    order: dict[str, Any] = {
        "speed": speeds,
        "speed_unit": "mm/s",
        "value": [s for _, s in inputs["order_points"]],
        "unit": "1",
        "provenance": order_prov,
        "source": order_src,
    }
    if inputs["order_sd"] is not None:
        order["sd"] = list(inputs["order_sd"])
    ratio = fitted["active.actuated_modulus_ratio"]
    ratio.update(relative_to=passive_name, temperature=model.actuation_temperature)
    active = {
        "kind": "active",
        "description": f"calibrated by rotomorph calibrate from {len(data.files)} table(s)",
        **singles(inputs["active"]),
        "modulus_law": "nematic-isotropic",
        "actuated_modulus_ratio": ratio,
        "transition_temperature": {**fitted["active.transition_temperature"], "unit": "C"},
        "transition_width": {**fitted["active.transition_width"], "unit": "C"},
        "hysteresis": _value(0.0, "C", "assumed", "no heating/cooling loop measured"),
        "strain_law": "threshold",
        "strain_gain": fitted["active.strain_gain"],
        "strain_threshold": fitted["active.strain_threshold"],
        "order_parameter": order,
        "director_pitch": _value(
            1.0,
            "1",
            "cited",
            "kinematic director helix tan(phi) = omega* r/R (Raney et al., PNAS 115, 1198 (2018))",
        ),
    }
    free_strain = {**fitted["passive.free_strain"], "temperature": model.actuation_temperature}
    passive = {
        "kind": "passive",
        "description": f"calibrated by rotomorph calibrate from {len(data.files)} table(s)",
        **singles(inputs["passive"]),
        "modulus_law": "entropic",
        "strain_law": "linear",
        "free_strain": free_strain,
    }
    s = settings
    doc = {
        "schema_version": 1,
        "name": settings.name,
        "version": "1",
        "description": "inks calibrated by rotomorph calibrate from the lab's measurement tables",
        "strain_measure": model.strain_model.measure,
        "conditions": {
            "print_temperature": stated(s.print_temperature, 25.0, "C", "--print-temperature"),
            "actuation_temperature": stated(
                s.actuation_temperature, 175.0, "C", "--actuation-temperature"
            ),
        },
        "nozzle": {
            "filament_radius": stated(s.radius, 0.3, "mm", "--radius"),
            "active_fraction": stated(s.active_fraction, 0.5, "1", "--active-fraction"),
        },
        "calibration": {
            "method": "rotomorph calibrate: maximum a posteriori with Gaussian priors on both "
            "modulus-ratio branches, weights 1/sd^2, Laplace covariance, leave-one-group-out",
            "tables": [f"{PurePath(name).name} (sha256 {sha[:16]})" for name, sha in data.files],
            "data_sha256": data.sha256,
            "chosen_branch": fit.label.replace("model.modulus_ratio", "E_a/E_p"),
            "branch_choice": joint.choice.replace("model.modulus_ratio", "E_a/E_p"),
            "determined": [FILE_KEYS[n][1] for n in after.determined],
            "at_prior": [FILE_KEYS[n][1] for n in after.at_prior],
            "report": settings.report,
            "parameters": [
                f"{active_name if FILE_KEYS[p.name][0] == 'active' else passive_name}."
                f"{FILE_KEYS[p.name][1]}"
                for p in params
            ],
            "coordinates": ["ln" if p.log else "linear" for p in params],
            "covariance": [
                [float(x) for x in row] for row in 0.5 * (fit.covariance + fit.covariance.T)
            ],
        },
        "inks": {active_name: active, passive_name: passive},
    }
    return materials_from_mapping(doc, "<rotomorph calibrate>")
