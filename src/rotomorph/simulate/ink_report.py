"""The calibration report of ``rotomorph calibrate`` (``calibration.md``), in words and tables.

Sections: what was read (tables and their hashes), what the tables determine (before and at
the fit), both branches of the bilayer symmetry and the choice, the fitted values and their
provenance, each table with its figure (measured, fitted, leave-one-group-out predicted, z),
the inputs used as measured, the validation-only rows, and every extrapolation range. Cells
that come from a measurement file are escaped: nothing a file holds reaches the page as markup.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from typing import Any

import numpy as np

from rotomorph.materials.lab_calibration import FILE_KEYS, LabCalibration
from rotomorph.materials.lab_tables import QUANTITIES

__all__ = ["report_markdown"]


def _cell(text: Any) -> str:
    """Markdown-inert text: markup characters escaped, one line, no control characters."""
    s = " ".join(str(text).split())
    s = "".join(c for c in s if c.isprintable())
    return re.sub(r"([\\`*_\[\]<>|~&$])", r"\\\1", s)


def _branch(text: str) -> str:
    return text.replace("model.modulus_ratio", "E_a/E_p")


def _num(x: float | None, sd: float | None = None) -> str:
    if x is None or not np.isfinite(x):
        return "—"
    if sd is None or not np.isfinite(sd):
        return f"{x:.4g}"
    return f"{x:.4g} ± {sd:.2g}"


def _z(z: float | None) -> str:
    return "—" if z is None or not np.isfinite(z) else f"{z:+.1f}"


def _ranges(cal: LabCalibration) -> list[str]:
    out = []
    pts = cal.inputs["order_points"]
    lo, hi = min(v for v, _ in pts), max(v for v, _ in pts)
    speeds = [m.x for m in cal.measurements.of("janus_curvature")]
    if speeds:
        lo, hi = min(lo, min(speeds)), max(hi, max(speeds))
    out.append(
        f"print speed: {lo:g} to {hi:g} mm/s (the order parameter is interpolated linearly in "
        "ln v between its points and extrapolated outside them: a prediction at another speed "
        "is an extrapolation)"
    )
    for q in ("pure_lce_length", "composite_length"):
        rows = cal.measurements.of(q)
        if rows:
            xs = [m.x for m in rows]
            out.append(f"{q}: ω* from {min(xs):g} to {max(xs):g}")
    temps = [m.x for q in ("free_length", "youngs_modulus") for m in cal.measurements.of(q)]
    m = cal.base.model
    t_lo = min([m.print_temperature, *temps])
    t_hi = max([m.actuation_temperature, *temps])
    out.append(
        f"temperature: {t_lo:g} to {t_hi:g} °C (the values at full actuation hold at the "
        f"actuation temperature {m.actuation_temperature:g} °C)"
    )
    out.append(
        f"section: filament radius {cal.base.radius:g} mm, active fraction "
        f"{cal.base.active_fraction:g} (other sections are computed with the same section "
        "theory but were not measured)"
    )
    return out


def report_markdown(
    cal: LabCalibration,
    validation: Sequence[Any],
    curves: dict[str, Any],
    materials_name: str,
    figures: Sequence[str],
) -> str:
    """The text of ``calibration.md`` (module docstring)."""
    data = cal.measurements
    inks = cal.materials
    fit = cal.fit
    lines = [
        f"# Calibration of {_cell(inks.name)}: {_cell(materials_name)}",
        "",
        f"Written by `rotomorph calibrate` from {len(data.files)} measurement table(s), "
        f"{len(data.rows)} rows; data sha256 `{data.sha256}`; materials sha256 "
        f"`{inks.sha256}`. Every calibrated value is a **fit** to these tables, not a "
        "measurement; the leave-one-group-out predictions are the out-of-sample check.",
        "",
        "| table | sha256 |",
        "| --- | --- |",
    ]
    lines += [f"| {_cell(f)} | `{s[:16]}…` |" for f, s in data.files]
    lines += ["", "## What the tables determine", "", "Before fitting (at the prior mean):", ""]
    lines += [f"* {_cell(t)}" for t in cal.before.lines()]
    lines += ["", "At the fitted optimum:", ""]
    lines += [f"* {_cell(t)}" for t in cal.after.lines()]
    if "identifiability.png" in figures:
        lines += ["", "![posterior over prior width of each parameter](identifiability.png)"]
    lines += ["", "## The two branches of the bilayer symmetry", ""]
    lines += [
        "A Janus bilayer's curvature depends on m = E_a/E_p through m + 1/m only (Timoshenko, "
        "J. Opt. Soc. Am. 11, 233 (1925)); both branches are fitted:",
        "",
        "| branch | χ² data | χ² prior | values |",
        "| --- | --- | --- | --- |",
    ]
    for b in cal.joint.branches:
        vals = ", ".join(f"{k.split('.')[-1]} {v:.4g}" for k, v in b.values.items())
        bound = f" (on a bound: {_branch(', '.join(b.at_bound))})" if b.at_bound else ""
        lines.append(
            f"| {_cell(_branch(b.label))}{_cell(bound)} | {b.chi2_data:.3f} | {b.chi2_prior:.3f} | "
            f"{_cell(vals)} |"
        )
    choice = _branch(cal.joint.choice)
    lines += ["", f"Chosen: {_cell(_branch(fit.label))}. {_cell(choice)}", ""]
    lines += ["## Fitted values and their priors", ""]
    lines += [
        "| parameter | written as | value | ±1 sd | prior | width ratio | status |",
        "| --- | --- | --- | --- | --- | --- | --- |",
    ]
    status = {p.name: p for p in cal.after.parameters}
    for p in cal.parameters:
        lo, hi = fit.intervals[p.name]
        prior = f"ln N({p.mean:.3g}, {p.sd:.3g})" if p.log else f"N({p.mean:.3g}, {p.sd:.3g})"
        role, key = FILE_KEYS[p.name]
        name = cal.inputs["names"][0 if role == "active" else 1]
        lines.append(
            f"| {_cell(status[p.name].label)} | `{_cell(name)}.{key}` | {fit.values[p.name]:.4g} "
            f"| [{lo:.4g}, {hi:.4g}] | {_cell(prior)} | {status[p.name].width_ratio:.2f} | "
            f"{status[p.name].status} |"
        )
    lines += ["", "## Each table: measured, fitted, predicted without it", ""]
    for g in cal.groups:
        rows = cal.group_rows(g.name)
        q = QUANTITIES[rows[0].quantity]
        lines += [f"### {g.name}", "", _cell(q.meaning) + ".", ""]
        if f"{g.name}.png" in figures:
            lines += [f"![{g.name}]({g.name}.png)", ""]
        fitted = np.asarray(g.predict(fit.model))
        held = cal.held_out.get(g.name)
        lines += [
            "| file, row | condition | x | measured | fitted (z) | predicted without this "
            "table | z |",
            "| --- | --- | --- | --- | --- | --- | --- |",
        ]
        for i, m in enumerate(rows):
            z_fit = (fitted[i] - m.value) / m.spread
            if held is None:
                pred, z = "— (no other table to fit)", None
            else:
                pred = _num(float(held[0][i]), float(held[1][i]))
                z = (held[0][i] - m.value) / np.hypot(m.spread, held[1][i])
            lines.append(
                f"| {_cell(m.file)}: {m.row} | {_cell(m.label)} | {_num(m.x)} | "
                f"{_num(m.value, m.spread)} | {_num(float(fitted[i]))} ({_z(z_fit)}) | "
                f"{_cell(pred)} | {_z(z)} |"
            )
        lines.append("")
    if "residuals.png" in figures:
        lines += ["![residuals of every row](residuals.png)", ""]
    lines += ["## Used as measured (inputs)", ""]
    a, p = cal.inputs["names"]
    for role, name in (("active", a), ("passive", p)):
        for key, (v, sd, prov, src) in cal.inputs[role].items():
            lines.append(f"* {_cell(name)} {key}: {_num(v, sd)} ({prov}: {_cell(src)})")
    prov, src = cal.inputs["order_provenance"]
    pts = ", ".join(f"S = {s:.4g} at {v:g} mm/s" for v, s in cal.inputs["order_points"])
    lines.append(f"* order parameter of {_cell(a)}: {pts} ({prov}: {_cell(src)})")
    lines += ["", "## Validation only (never fitted)", ""]
    if not validation:
        lines.append("No validation rows (sinusoid_end_to_end, lattice_area) were given.")
    else:
        lines += [
            "| file, row | quantity | condition | measured | predicted | z | how |",
            "| --- | --- | --- | --- | --- | --- | --- |",
        ]
        for v in validation:
            m = v.measurement
            z = None
            if v.predicted is not None:
                z = (v.predicted - m.value) / float(np.hypot(m.spread, v.sd or 0.0))
            lines.append(
                f"| {_cell(m.file)}: {m.row} | {m.quantity} | {_cell(m.label)} | "
                f"{_num(m.value, m.spread)} | {_num(v.predicted, v.sd)} | {_z(z)} | "
                f"{_cell(v.how)} |"
            )
    lines += ["", "## Where the model is measured (extrapolation ranges)", ""]
    lines += [f"* {_cell(t)}" for t in _ranges(cal)]
    lines += ["", f"## Every value of {_cell(materials_name)}", ""]
    lines += ["| ink | key | value | unit | sd | provenance | source |"]
    lines += ["| --- | --- | --- | --- | --- | --- | --- |"]
    for r in inks.values():
        value = r.value if isinstance(r.value, str) else f"{r.value:.6g}"
        lines.append(
            f"| {_cell(r.owner)} | {r.key} | {_cell(value)} | {_cell(r.unit)} | "
            f"{_num(r.sd)} | {r.provenance} | {_cell(r.source)} |"
        )
    return "\n".join(lines) + "\n"
