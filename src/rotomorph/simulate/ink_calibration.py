"""``rotomorph calibrate``: a lab's measurement tables → its materials file and a calibration
report.

:func:`calibrate_files` reads the tables (:mod:`rotomorph.io.measurement_csv`), calibrates the
two inks (:func:`rotomorph.materials.lab_calibration.calibrate_tables`), predicts the
validation-only rows with the calibrated file exactly as ``rotomorph simulate`` would
(sinusoids: the zero-energy free shape; lattices: the contact-resolved heating ramp on the bath
floor under buoyant weight) and writes

* ``INKS.toml``: the materials file (posterior means, sd, provenance, the data's hash);
* ``INKS_calibration/calibration.md``: identifiability in words, both branches, each table
  with its fitted curve and band, the residuals, the leave-one-group-out predictions with z,
  the validation rows and every extrapolation range; ``calibration.json``; the figures.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.io.atomic import atomic_folder, atomic_write_text
from rotomorph.io.materials_file import save_materials
from rotomorph.io.measurement_csv import read_measurements
from rotomorph.materials.lab_calibration import (
    CalibrationSettings,
    LabCalibration,
    calibrate_tables,
)
from rotomorph.materials.lab_model import InkPair, curve
from rotomorph.materials.lab_tables import QUANTITIES, Measurement
from rotomorph.materials.natural import natural_field
from rotomorph.rod.model import Model
from rotomorph.simulate.free_shape import free_equilibrium, min_clearance
from rotomorph.simulate.ink_report import report_markdown

__all__ = ["CalibrationRun", "ValidationRow", "calibrate_files", "predict_validation"]

logger = logging.getLogger("rotomorph.progress")

#: Vertex spacing (mm) of the sinusoid predictions (the report's finer resolution).
SINUSOID_SPACING = 0.05
#: Heating steps of the lattice predictions (as the report's counted ramps).
LATTICE_STEPS = 8

AXES = {
    "janus_curvature": ("print speed v (mm/s)", "Janus curvature K_J (1/mm)", False),
    "pure_lce_length": ("rotation number ω* (–)", "L/L0 of pure active filaments (–)", True),
    "composite_length": ("rotation number ω* (–)", "L/L0 of Janus filaments (–)", True),
    "free_length_active": ("temperature T (°C)", "free length L/L0, active ink (–)", False),
    "free_length_passive": ("temperature T (°C)", "free length L/L0, passive ink (–)", False),
    "youngs_modulus_active": ("temperature T (°C)", "E of the active ink (MPa)", False),
    "youngs_modulus_passive": ("temperature T (°C)", "E of the passive ink (MPa)", False),
}


@dataclass(frozen=True)
class ValidationRow:
    """A validation-only measurement and its prediction by the calibrated file."""

    measurement: Measurement
    predicted: float | None
    sd: float | None
    how: str


@dataclass(frozen=True, eq=False)
class CalibrationRun:
    """What :func:`calibrate_files` computed and wrote."""

    calibration: LabCalibration
    validation: tuple[ValidationRow, ...]
    materials_path: Path
    report_folder: Path
    figures: tuple[Path, ...] = ()
    curves: dict[str, Any] = field(default_factory=dict)

    def identifiability_lines(self) -> list[str]:
        """What the tables determine at the fitted optimum, in words: one line per parameter
        (determined by which tables, or at its prior and which measurement would pin it down),
        then the singular values."""
        return self.calibration.after.lines()

    def summary_line(self) -> str:
        """One line for the terminal."""
        cal = self.calibration
        det, prior = cal.after.determined, cal.after.at_prior
        words = lambda names: ", ".join(n.split(".")[-1] for n in names) or "none"  # noqa: E731
        return (
            f"wrote {self.materials_path} and {self.report_folder}/calibration.md: "
            f"{len(cal.measurements.rows)} rows of {len(cal.measurements.files)} table(s); "
            f"determined: {words(det)}; at their priors: {words(prior)}; branch "
            f"{cal.fit.label.replace('model.modulus_ratio', 'E_a/E_p')}"
        )


def _sinusoid(m: Measurement, pair: InkPair, names: tuple[str, str], inks: Any) -> Any:
    from rotomorph.io.designfile import Filament

    c = m.conditions
    data = {
        "name": f"sinusoid ({c['side']})",
        "speed": float(c["v"]),
        "active_side": str(c["side"]),
        "spacing": SINUSOID_SPACING,
        "radius": pair.radius,
        "active_fraction": pair.active_fraction,
        "active_material": names[0],
        "passive_material": names[1],
        "segments": [
            {
                "kind": "sinusoid",
                "amplitude": float(c["A"]),
                "wavelength": float(c["wavelength"]),
                "periods": float(c["periods"]),
            }
        ],
    }
    return Filament.model_validate(data, context={"materials": inks}).to_program()


def _sinusoid_shape(program: Any, pair: InkPair, resolution: int) -> FloatArray:
    mats = {program.active_material: pair.active, program.passive_material: pair.passive}
    model = replace(pair.model, resolution=resolution)
    field_ = natural_field(program, mats, model.actuation_temperature, model=model)
    return free_equilibrium(Model.from_field(program.points, field_))


def _sinusoid_ratio(program: Any, pair: InkPair, resolution: int) -> float:
    shape = _sinusoid_shape(program, pair, resolution)
    p = program.points
    return float(np.linalg.norm(shape[-1] - shape[0]) / np.linalg.norm(p[-1] - p[0]))


def _lattice_area(m: Measurement, cal: LabCalibration) -> tuple[float, str]:
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.lattice.actuation import ProgramActuation
    from rotomorph.lattice.heating import heat_lattice, lattice_buoyancy
    from rotomorph.simulate.surroundings import _density

    c = m.conditions
    a, p = cal.inputs["names"]
    inks = cal.materials
    lattice = sinusoidal_lattice(
        round(float(c["n"])),
        float(c["l"]),
        float(c["A"]),
        round(float(c.get("ghost_nodes", 10))),
        str(c["pattern"]),  # type: ignore[arg-type]
        layers=round(float(c.get("layers", 3))),
        speed=float(c["v"]),
        radius=cal.base.radius,
        active_fraction=cal.base.active_fraction,
        active_material=a,
        passive_material=p,
    )
    fm = inks.filament_model(a, p)
    result = heat_lattice(
        lattice,
        actuation=ProgramActuation(filament_model=fm),
        steps=LATTICE_STEPS,
        contact=True,
        floor=True,
        gravity=lattice_buoyancy(lattice, density=_density(a, p, 0.5, inks)),
    )
    stable = result.stable[-1] if result.stable else None
    clearance = float(result.min_clearance[-1])
    verdict = (
        "physical"
        if stable is True and clearance >= 1.0 - 1e-6
        else "NOT PHYSICAL"
        if stable is False or clearance < 1.0 - 1e-6
        else "stability not checked"
    )
    state = (
        f"{verdict}: final state {'certified stable' if stable else 'not certified stable'}, "
        f"closest approach {clearance:.2f} diameters"
    )
    return 100.0 * (float(result.final_area_ratio) - 1.0), state


def predict_validation(cal: LabCalibration, *, lattices: bool = True) -> tuple[ValidationRow, ...]:
    """Predictions of the validation-only rows by the calibrated model (module docstring)."""
    out = []
    names = cal.inputs["names"]
    for m in cal.measurements.rows:
        if QUANTITIES[m.quantity].role != "validation":
            continue
        if m.quantity == "sinusoid_end_to_end":
            program = _sinusoid(m, cal.base, names, cal.materials)

            def ratio(pair: InkPair, program: Any = program) -> FloatArray:
                return np.array([_sinusoid_ratio(program, pair, 96)])

            value, sd = cal.fit.propagate(ratio, central=False)
            diameter = 2.0 * cal.base.radius
            gap = (
                min_clearance(
                    _sinusoid_shape(program, cal.fit.model, 96), exclude_arc=2.0 * diameter
                )
                / diameter
            )
            state = "physical" if gap >= 1.0 else "NOT PHYSICAL (passes through itself)"
            out.append(
                ValidationRow(
                    m, float(value[0]), float(sd[0]),
                    f"zero-energy free shape, ideal flips, spacing {SINUSOID_SPACING} mm; "
                    f"{state}: closest approach {gap:.2f} diameters",
                )
            )  # fmt: skip
        elif not lattices:
            out.append(ValidationRow(m, None, None, "not computed (--no-lattices)"))
        else:
            logger.info("validation: %s lattice ramp (%s)", m.conditions["pattern"], m.label)
            area, state = _lattice_area(m, cal)
            out.append(
                ValidationRow(
                    m, area, None,
                    f"contact-resolved ramp on the bath floor, buoyant weight, {LATTICE_STEPS} "
                    f"steps, no calibration sd; {state}",
                )
            )  # fmt: skip
    return tuple(out)


def _group_curves(
    cal: LabCalibration,
) -> dict[str, list[tuple[str, FloatArray, FloatArray, FloatArray]]]:
    """Per fitted group: (label, x, model, sd) dense curves of the chosen fit."""
    out: dict[str, list[tuple[str, FloatArray, FloatArray, FloatArray]]] = {}
    t0, t1 = cal.base.model.print_temperature, cal.base.model.actuation_temperature
    for g in cal.groups:
        rows = cal.group_rows(g.name)
        quantity = rows[0].quantity
        role = rows[0].ink[0] if rows[0].ink else ""
        xs = np.array([m.x for m in rows])
        curves: list[tuple[str, FloatArray, dict[str, Any]]] = []
        if quantity == "janus_curvature":
            lo = min(xs.min(), min(v for v, _ in cal.inputs["order_points"]))
            dense = np.linspace(max(lo * 0.5, 1e-3), xs.max() * 1.15, 80)
            for t in sorted({float(m.conditions.get("T", t1)) for m in rows}):
                curves.append((f"fit to all tables, {t:g} °C", dense, {"temperature": t}))
        elif quantity in ("pure_lce_length", "composite_length"):
            dense = np.geomspace(max(xs.min() * 0.6, 1e-3), xs.max() * 1.3, 60)
            for v in sorted({float(m.conditions["v"]) for m in rows}):
                curves.append((f"fit to all tables, v = {v:g} mm/s", dense, {"speed": v}))
        elif quantity == "free_length" and role == "active":
            dense = np.linspace(t0, max(xs.max(), t1), 60)
            for v in sorted({float(m.conditions["v"]) for m in rows}):
                curves.append((f"fit, v = {v:g} mm/s", dense, {"speed": v, "role": role}))
        else:
            dense = np.linspace(t0, max(xs.max(), t1), 60)
            curves.append(("fit to all tables", dense, {"role": role}))
        done = []
        for label, x, kw in curves:

            def q(
                pair: InkPair, x: FloatArray = x, kw: dict = kw, quantity: str = quantity
            ) -> FloatArray:
                return curve(quantity, pair, x, **kw)

            y, sd = cal.fit.propagate(q)
            done.append((label, x, y, sd))
        out[g.name] = done
    return out


def _figures(cal: LabCalibration, curves: dict[str, Any], folder: Path) -> list[Path]:
    from rotomorph.plot.calibration import (
        Curve,
        Points,
        fit_figure,
        identifiability_figure,
        residual_figure,
    )
    from rotomorph.plot.figure import save_figure

    paths = []
    for g in cal.groups:
        rows = cal.group_rows(g.name)
        xlabel, ylabel, log_x = AXES[g.name]
        measured = [
            Points(
                np.array([m.x for m in rows]),
                np.array([m.value for m in rows]),
                np.array([m.spread for m in rows]),
                "measured (mean ± sd)",
            )
        ]
        held = cal.held_out.get(g.name)
        held_pts = (
            None
            if held is None
            else Points(measured[0].x, held[0], held[1], "predicted without this table (± sd)")
        )
        fig = fit_figure(
            measured,
            [Curve(x, y, sd, label) for label, x, y, sd in curves[g.name]],
            held_pts,
            xlabel=xlabel,
            ylabel=ylabel,
            title=f"{g.name}: fit (band ± 1 sd of the calibration)",
            log_x=log_x,
        )
        paths.append(save_figure(fig, folder / f"{g.name}.png"))
    names, z_in, z_out = [], [], []
    fitted = {g.name: np.asarray(g.predict(cal.fit.model)) for g in cal.groups}
    for g in cal.groups:
        names.append(g.name)
        z_in.append((fitted[g.name] - g.table.value) / g.table.spread)
        held = cal.held_out.get(g.name)
        z_out.append(
            None if held is None else (held[0] - g.table.value) / np.hypot(g.table.spread, held[1])
        )
    paths.append(save_figure(residual_figure(names, z_in, z_out), folder / "residuals.png"))
    labels = [p.label for p in cal.after.parameters]
    fig = identifiability_figure(
        labels,
        [p.width_ratio for p in cal.before.parameters],
        [p.width_ratio for p in cal.after.parameters],
    )
    paths.append(save_figure(fig, folder / "identifiability.png"))
    return paths


def calibrate_files(
    measurements: Sequence[str | Path],
    output: str | Path,
    settings: CalibrationSettings | None = None,
    *,
    lattices: bool = True,
    figures: bool = True,
    progress: Callable[[str], None] | None = None,
) -> CalibrationRun:
    """Calibrate from measurement files and write the materials file and its report.

    Parameters
    ----------
    measurements
        CSV tables (module :mod:`rotomorph.io.measurement_csv`).
    output
        The materials file to write (``.toml``); the report goes to ``<stem>_calibration/``
        beside it (replaced when it exists).
    settings
        What the tables do not say (:class:`CalibrationSettings`).
    lattices
        Predict validation rows of lattices (contact-resolved ramps, seconds to minutes each).
    figures
        Draw the figures.
    progress
        Called with a phase message.

    Raises
    ------
    InvalidParameterError
        Bad tables (file, row, column) or a missing measurement.
    """
    say = progress or (lambda text: logger.info("%s", text))
    out = Path(output)
    folder = out.with_name(out.stem + "_calibration")
    settings = replace(
        CalibrationSettings() if settings is None else settings,
        report=f"{folder.name}/calibration.md",
    )
    say("reading the measurement tables")
    data = read_measurements(measurements)
    say("identifiability, then the joint fit on both branches and leave-one-group-out refits")
    cal = calibrate_tables(data, settings)
    say("validation rows and the calibration bands")
    validation = predict_validation(cal, lattices=lattices)
    curves = _group_curves(cal)
    written: list[Path] = []
    with atomic_folder(folder) as tmp:
        figs = _figures(cal, curves, tmp) if figures else []
        text = report_markdown(cal, validation, curves, out.name, [p.name for p in figs])
        atomic_write_text(tmp / "calibration.md", text)
        record = _record(cal, validation)
        atomic_write_text(tmp / "calibration.json", json.dumps(record, indent=2) + "\n")
        written = [folder / p.name for p in figs]
    save_materials(cal.materials, out)
    return CalibrationRun(cal, validation, out, folder, tuple(written), curves)


def _record(cal: LabCalibration, validation: Sequence[ValidationRow]) -> dict[str, Any]:
    def rows_of(g: Any) -> list[dict[str, Any]]:
        held = cal.held_out.get(g.name)
        fitted = np.asarray(g.predict(cal.fit.model))
        out = []
        for i, m in enumerate(cal.group_rows(g.name)):
            row = {
                "file": m.file,
                "row": m.row,
                "condition": m.label,
                "x": None if np.isnan(m.x) else m.x,
                "measured": m.value,
                "spread": m.spread,
                "fitted": float(fitted[i]),
                "z_fitted": float((fitted[i] - m.value) / m.spread),
            }
            if held is not None:
                comb = float(np.hypot(m.spread, held[1][i]))
                row.update(
                    predicted=float(held[0][i]),
                    predicted_sd=float(held[1][i]),
                    z=float((held[0][i] - m.value) / comb),
                )
            out.append(row)
        return out

    return {
        "materials": cal.materials.record(),
        "data_sha256": cal.measurements.sha256,
        "tables": [{"file": f, "sha256": s} for f, s in cal.measurements.files],
        "calibration": cal.joint.record(),
        "identifiability_before": cal.before.record(),
        "identifiability_after": cal.after.record(),
        "groups": {g.name: rows_of(g) for g in cal.groups},
        "validation": [
            {
                "file": v.measurement.file,
                "row": v.measurement.row,
                "quantity": v.measurement.quantity,
                "condition": v.measurement.label,
                "measured": v.measurement.value,
                "spread": v.measurement.spread,
                "predicted": v.predicted,
                "predicted_sd": v.sd,
                "how": v.how,
            }
            for v in validation
        ],
    }
