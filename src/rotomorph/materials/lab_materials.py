"""The materials file a lab calibration writes: measured inputs, fitted values, provenance.

Fitted values are ``calibrated`` (the maximum a posteriori, its sd and, for values fitted on a
log scale, the ±1 sd interval; the source names the prior, the tables that inform the value
and the data's hash), or ``assumed`` where the tables leave them at their priors; the file's
``[calibration]`` table records the method, the tables and their hashes, the branch choice,
which values the tables determine, and the posterior covariance.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import PurePath
from typing import TYPE_CHECKING, Any, Final

from rotomorph.materials.identifiability import Identifiability
from rotomorph.materials.inference import Fit, JointCalibration, Parameter
from rotomorph.materials.lab_model import InkPair
from rotomorph.materials.lab_tables import MeasurementSet
from rotomorph.materials.parameter_set import MaterialSet, materials_from_mapping

if TYPE_CHECKING:
    from rotomorph.materials.lab_calibration import CalibrationSettings

__all__ = ["FILE_KEYS", "materials_set"]

#: Keys of the materials file the fitted parameters are written to: (ink role, key).
FILE_KEYS: Final = {
    "model.modulus_ratio": ("active", "actuated_modulus_ratio"),
    "model.strain_model.gain": ("active", "strain_gain"),
    "model.strain_model.threshold": ("active", "strain_threshold"),
    "model.passive_strain": ("passive", "free_strain"),
    "active.transition_temperature": ("active", "transition_temperature"),
    "model.transition_width": ("active", "transition_width"),
}


def _value(value: float, unit: str, provenance: str, source: str, **extra: Any) -> dict[str, Any]:
    out: dict[str, Any] = {"value": float(value), "unit": unit, "provenance": provenance}
    out["source"] = source
    out.update({k: v for k, v in extra.items() if v is not None})
    return out


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


def materials_set(
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
