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
says which parameters the tables determine; a table set that cannot determine the strain law
(its gain and threshold), or that lacks either ink's modulus at the print temperature, is
refused (:class:`~rotomorph.errors.InvalidParameterError`, one line naming the missing
measurement). :func:`calibrate_tables` returns the fit, the identifiability before
and after it, the leave-one-group-out predictions and the :class:`MaterialSet` to write.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, Final

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.errors import InvalidParameterError
from rotomorph.materials.identifiability import Identifiability, identifiability
from rotomorph.materials.inference import Fit, Group, JointCalibration, Parameter, joint_calibrate
from rotomorph.materials.lab_inputs import groups as group_rows
from rotomorph.materials.lab_inputs import ink_inputs, order_points
from rotomorph.materials.lab_materials import FILE_KEYS, materials_set
from rotomorph.materials.lab_model import InkPair, predictor
from rotomorph.materials.lab_tables import Measurement, MeasurementSet, table
from rotomorph.materials.material import Material
from rotomorph.materials.natural import FilamentModel
from rotomorph.materials.parameter_set import MaterialSet
from rotomorph.materials.process import EmpiricalThreshold, order_parameter

#: Phase messages (the command line shows them on a terminal or with --verbose).
progress = logging.getLogger("rotomorph.progress")

__all__ = [
    "ESSENTIAL",
    "FILE_KEYS",
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
BRANCH_REASON: Final = (
    "E_a >= E_p at actuation assumed: no table distinguishes the two branches of the bilayer "
    "symmetry; measure both inks' moduli at the actuation temperature to decide"
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
    a_in = ink_inputs(data, "active", active_name, t_print)
    p_in = ink_inputs(data, "passive", passive_name, t_print)
    points, point_sd, point_prov, point_src = order_points(data)
    rows = group_rows(data, t_print)
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
    progress.info("what the tables determine, before fitting:")
    for line in before.lines():
        progress.info("  %s", line)
    progress.info("fitting (both branches of the bilayer symmetry, then leave-one-group-out)")
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
    inks = materials_set(data, settings, base, params, joint, after, inputs)
    return LabCalibration(
        data, settings, base, params, groups, joint, before, after, held_out, inks, inputs
    )
