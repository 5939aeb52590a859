"""The paper report: every measured quantity of the paper, measured vs predicted out of sample.

:func:`paper_report` writes into a folder (which must exist)::

    report.md                 Markdown: calibration, tables (measured, predicted ± sd, z,
                              fit or prediction, converged) and the figures
    summary.json              list of rows, one per measured quantity: quantity, condition,
                              measured, spread, predicted, predicted_sd, error, z, calibration,
                              counted, converged, discretisation_error, resolution, note, unit,
                              figure (:mod:`rotomorph.simulate.validation`)
    prediction_table.md       the README's prediction table (one line per measured quantity)
    published_fig4_sweep.json the authors' own Fig. 4 simulation rebuilt: its stretch sweep
                              (:mod:`rotomorph.simulate.report_published`)
    calibration.json          the joint calibrations (both modulus-ratio branches, the choice and
                              why, priors) and the out-of-sample score
    figures/*.png

Predictions are leave-one-group-out (:mod:`rotomorph.simulate.validation`): each group of
measurements is predicted by the model calibrated without it; rows that are fits or inputs have
``calibration = true`` and are never counted. Every number is computed at two resolutions; the
report fails loudly (:class:`~rotomorph.errors.ConvergenceError`, after writing everything) when
a number is not converged to 1 % unless ``allow_unconverged``. Every counted contact-resolved
lattice ramp is also run with each step split into :data:`PATH_CHECK_FACTOR` sub-steps; where
the two end in different stable states (a multistable lattice), the one lower in total energy
is counted (:mod:`rotomorph.lattice.paths`) and the row's note says so.

Sections: Janus curvature vs speed (Fig. 2D), L/L0 vs ω* (Fig. 2F/G), sinusoidal filaments
(Fig. 3C/D), lattice areas (Fig. 3G), dome and saddle lattices (Fig. 4), and the authors' own
simulation of Fig. 4 rebuilt (no rows: it compares two simulations, not a measurement). A
lattice part that fails becomes rows with ``predicted = null`` and the reason in ``note``.
"""

from __future__ import annotations

import json
import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

import rotomorph
from rotomorph._typing import FloatArray
from rotomorph.errors import ConvergenceError, RotomorphError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.results import write_summary
from rotomorph.materials import FilamentModel, load_table
from rotomorph.materials.calibrate import filament_shapes, janus_curvature
from rotomorph.materials.inference import Fit
from rotomorph.simulate.bands import WEAK_RULE, Band, finish_row, plain_row
from rotomorph.simulate.cache import disk_cached
from rotomorph.simulate.nuisance import nominal_sample, priors_record
from rotomorph.simulate.report_shapes import (
    filament_shapes_figure,
    free_shape_normals,
    lattice_tube_figure,
)
from rotomorph.simulate.validation import (
    CONVERGENCE_RTOL,
    FILAMENT_SPACINGS,
    SINUSOID_DESIGN,
    Validation,
    at_resolution,
    free_shape,
    row,
    sinusoid_shape,
    summarise,
    summary_line,
    validate_filaments,
)

__all__ = [
    "PaperReport",
    "calibrated_model",
    "lattice_rows",
    "paper_report",
    "paper_rows",
    "prediction_table",
]

logger = logging.getLogger(__name__)
#: What the report is computing, for the command line's progress display.
phase_log = logging.getLogger("rotomorph.progress")

Progress = Callable[[int, int], None]

ROTATION_NUMBERS = (0.06, 0.25, 1.0, 2.0)
FILAMENT_LENGTH = 30.0  # mm, as in examples/designs
_row = row


def _end_physical(res: Any) -> tuple[bool, str]:
    """Whether a lattice ramp's end state is physical (certified stable and admissible: no two
    layers of its printed stack interpenetrate, :mod:`rotomorph.lattice.admissibility`), and
    what fails ("" when nothing does)."""
    if res is None:
        return False, "no state"
    why = []
    if not bool(res.stable[-1]):
        why.append("not certified stable")
    overlaps = getattr(res, "stack_overlaps", None)
    if overlaps is None:
        why.append("stack admissibility not checked")
    elif int(overlaps[-1]) > 0:
        why.append(f"{int(overlaps[-1])} layer pairs of the printed stack interpenetrate")
    return not why, "; ".join(why)


def _surface(lattice: Any, res: Any) -> Any:
    """How the end state reads as a surface (:func:`rotomorph.analysis.surface.surface_quality`)."""
    from rotomorph.analysis.surface import surface_quality

    return surface_quality(res.positions[-1], lattice.branch_indices, lattice.edge_chains)


def _surface_record(lattice: Any, res: Any) -> dict[str, Any]:
    q = _surface(lattice, res)
    return {
        "residual_over_rise": round(q.relative_residual, 4),
        "rise_mm": round(q.rise, 3),
        "crossing_edges": len(q.crossing_edges),
        "is_surface": bool(q.is_surface),
    }


def _surface_text(lattice: Any, res: Any) -> str:
    q = _surface(lattice, res)
    verdict = "yes" if q.is_surface else "no"
    return f"{verdict} ({q.text()}; docs/validation.md, *Lattices as printed*)"


def _flagged(title: str, res: Any) -> tuple[str, str]:
    """A figure title with NOT PHYSICAL (and its reason) added where the end state is not
    physical, and the title's colour."""
    ok, why = _end_physical(res)
    return (title, "k") if ok else (f"{title}\nNOT PHYSICAL: {why}", "tab:red")


@dataclass(frozen=True)
class PaperReport:
    """What :func:`paper_report` wrote.

    Attributes
    ----------
    rows
        The summary rows (see module docstring).
    figures
        Figure paths.
    parameters
        Calibrated model parameters by name (fit to all calibration groups).
    wall_time
        Seconds spent.
    summary
        Out-of-sample score (:func:`rotomorph.simulate.validation.summarise`).
    """

    rows: list[dict[str, Any]]
    figures: list[Path]
    parameters: dict[str, float]
    wall_time: float
    timings: dict[str, float] = field(default_factory=dict)
    summary: dict[str, Any] = field(default_factory=dict)


def calibrated_model() -> tuple[FilamentModel, dict[str, float]]:
    """The model calibrated jointly on all filament groups and its parameters.

    Used for the never-fitted groups (sinusoids, lattices); each calibration group is predicted
    by the fit without it (:func:`rotomorph.simulate.validation.validate_filaments`).
    """
    from rotomorph.materials.calibrate import paper_calibration

    fit = paper_calibration().chosen
    return at_resolution(fit.model), fit.values


# ----------------------------------------------------------------------------- sections


def _curvature_section(val: Validation, figs: Path) -> tuple[list[dict], list[Path]]:
    from rotomorph.plot.figure import save_figure
    from rotomorph.plot.report import plot_measured_vs_predicted

    table = load_table("janus_curvature")
    rows = [r for r in val.rows if r["quantity"] == "janus_curvature"]
    v = np.linspace(0.1, 3.5, 80)
    fig = plot_measured_vs_predicted(
        table.x,
        table.value,
        table.spread,
        janus_curvature(val.model, v),
        predicted_x=v,
        xlabel="print speed v (mm/s)",
        ylabel="curvature of the heated filament K_J (1/mm of its length)",
        predicted_label="fit to all filament groups",
        title="Fig. 2D: curvature vs print speed (ω* = 0)",
        out_of_sample=(
            table.x,
            np.array([r["predicted"] for r in rows]),
            np.array([r["predicted_sd"] for r in rows]),
        ),
    )
    return rows, [save_figure(fig, figs / "fig2d_janus_curvature.png")]


def _straight(fraction: float, omega_star: float, spacing: float) -> Any:
    from rotomorph.io.designfile import Filament

    return Filament(
        speed=3.0,
        rotation_number=omega_star,
        radius=0.3,
        active_fraction=fraction,
        spacing=spacing,
        segments=[{"kind": "line", "length": FILAMENT_LENGTH}],  # type: ignore[list-item]
    ).to_program()


def _rotation_section(val: Validation, figs: Path) -> tuple[list[dict], list[Path]]:
    from rotomorph.plot.figure import new_figure, save_figure

    model = val.model
    rows: list[dict] = []
    shapes: dict[tuple[str, float], Any] = {}
    fig = new_figure(10.0, 4.2)
    axes = fig.subplots(1, 2)
    dense = np.geomspace(0.02, 3.0, 120)
    for ax, (table_name, fraction, label) in zip(
        axes,
        (("pure_lce_length", 1.0, "pure LCE"), ("composite_length", 0.5, "composite")),
        strict=True,
    ):
        table = load_table(table_name)
        sel = [r for r in val.rows if r["quantity"] == f"{table_name}_L_over_L0"]
        rows += sel
        for w in ROTATION_NUMBERS:
            prog = _straight(fraction, w, FILAMENT_SPACINGS[0])
            x = free_shape(prog, model)
            shapes[(label, w)] = (prog, x, free_shape_normals(prog, model, x))
        curve = [s.end_to_end_ratio for s in filament_shapes(model, dense, fraction)]
        ax.plot(dense, curve, "k-", lw=1, label="free helix, fit to all groups")
        ax.errorbar(
            table.x * 1.04,
            [r["predicted"] for r in sel],
            yerr=[r["predicted_sd"] or 0.0 for r in sel],
            fmt="rs",
            ms=5,
            capsize=3,
            label="predicted without this group (± sd)",
        )
        ax.errorbar(table.x, table.value, yerr=table.spread, fmt="o", color="tab:blue",
                    capsize=3, label="measured")  # fmt: skip
        ax.set_xscale("log")
        ax.set_xlabel("ω* = Rω/v (–)")
        ax.set_ylabel("L/L0 (–)")
        ax.set_title(f"Fig. 2{'F' if fraction == 1.0 else 'G'}: {label}")
        ax.set_ylim(0, 1.1)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    paths = [save_figure(fig, figs / "fig2fg_length_vs_rotation.png")]
    paths.append(_shapes_figure(shapes, figs / "fig2fg_shapes.png"))
    return rows, paths


def _shapes_figure(shapes: dict[tuple[str, float], Any], path: Path) -> Path:
    from rotomorph.plot.figure import save_figure

    return save_figure(filament_shapes_figure(shapes), path)


def _sinusoid_section(val: Validation, figs: Path) -> tuple[list[dict], list[Path]]:
    from rotomorph.plot.figure import new_figure, save_figure
    from rotomorph.simulate.nuisance_filaments import (
        FLIP_SPACINGS,
        STEP_SPACINGS,
        heated_shape,
        sinusoid_program,
    )
    from rotomorph.simulate.validation import _program

    rows = [r for r in val.rows if r["quantity"] == "sinusoid_end_to_end_ratio"]
    shown = [r for r in rows if r["counted"] or "printable" not in r["condition"]]
    nominal = nominal_sample()
    spacing = (FLIP_SPACINGS if nominal.flip_length > 0 else STEP_SPACINGS)[1]
    fig = new_figure(10.0, 4.6)
    axes = fig.subplots(1, 2)
    for i, (side, label) in enumerate((("outer", "expanding"), ("inner", "contracting"))):
        prog = sinusoid_program(side, nominal, spacing)
        x = heated_shape(side, val.model, nominal)
        x = x - x[0] + prog.points[0]
        ax = axes[i]
        ax.plot(prog.points[:, 0], prog.points[:, 1], "k--", lw=1,
                label=f"printed: l = {nominal.cell_size:.3g} mm, A = l/4")  # fmt: skip
        contact = " (self-contact)" if shown[i].get("contact_resolved") else ""
        ax.plot(x[:, 0], x[:, 1], "r-", lw=1,
                label=f"175 °C{contact}: L/L0 = {shown[i]['predicted']:.2f} "
                f"± {shown[i]['predicted_sd'] or 0:.2f}")  # fmt: skip
        flip = SINUSOID_DESIGN["flip_length"]
        p5 = _program(side, FILAMENT_SPACINGS[1], flip)
        xp = sinusoid_shape(side, val.model, FILAMENT_SPACINGS[1], flip)
        shift = np.array([0.0, -2.5 * nominal.amplitude - 2.0 * SINUSOID_DESIGN["amplitude"], 0])
        ax.plot(p5.points[:, 0] + shift[0], p5.points[:, 1] + shift[1], "k:", lw=0.8,
                label="design file (l = 5 mm, 0.5 mm flips): printed")  # fmt: skip
        xp = xp - xp[0] + p5.points[0] + shift
        ax.plot(xp[:, 0], xp[:, 1], "b-", lw=0.8, label="design file: 175 °C (not counted)")
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.18))
        ax.set_aspect("equal", adjustable="datalim")
        ax.set_title(
            f"Fig. 3{'C' if side == 'outer' else 'D'}: {label} (active {side}), measured "
            f"{shown[i]['measured']:.2f} ± {shown[i]['spread']:.2f}",
            fontsize=9,
        )
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
    fig.subplots_adjust(bottom=0.32)
    return rows, [save_figure(fig, figs / "fig3cd_sinusoids.png")]


#: Ghost nodes per lattice edge at the two resolutions (quick, full).
LATTICE_GHOSTS = {True: (6, 12), False: (10, 20)}
#: Heating steps of the full lattice ramps.
LATTICE_STEPS = 8
#: Every counted contact-resolved lattice ramp is also run with each step split into this many
#: sub-steps: a lattice with several stable states can end in a different one when the path
#: changes (path dependence), and then the end state lower in total energy is counted
#: (``heat_lattice(..., path_check=...)``).
PATH_CHECK_FACTOR = 2
#: Width (°C) to which the dome's and saddle's lift-off and weightless buckling are bisected.
LIFT_OFF_TOLERANCE = 0.5


#: Heating steps of the perturbed ramps that propagate the calibration's uncertainty (the
#: secants compare ramps of the same steps, without contact: no lift-off, no jamming).
SD_STEPS = 4


def _heat(
    pattern: str,
    quick: bool,
    steps: int,
    model: FilamentModel,
    ghosts: int,
    contact: bool = False,
    branch: str = "lowest",
    lift_off_tolerance: float | None = None,
    path_check: int = 1,
) -> tuple[Any, Any, str]:
    """(lattice, HeatingResult or None, reason): heated through the materials chain;
    ``contact``: with self-contact, resting on the bath floor under its buoyant weight;
    ``branch``: which equilibrium a lattice resting on the floor follows (``heat_lattice``)."""
    try:
        from rotomorph.lattice import actuation as modes
        from rotomorph.lattice.heating import heat_lattice
    except ImportError as err:  # pragma: no cover - module missing
        return None, None, f"lattice module not available ({err})"
    # each edge from its print program where the lattice layer provides it, else every edge
    # with the Janus section's curvature and centre-line strain at the print speed
    mode = getattr(modes, "ProgramActuation", modes.ThermalActuation)
    from rotomorph.design.lattices import sinusoidal_lattice

    n = 3 if quick else 5
    phase_log.info(
        "%s %dx%d lattice (%d ghost nodes, %d steps, %s)",
        pattern,
        n,
        n,
        ghosts,
        steps,
        "on the floor, contact" if contact else "no contact",
        extra={"task": True},
    )
    lattice = sinusoidal_lattice(n, 5.0, 1.25, ghosts, pattern)  # type: ignore[arg-type]
    try:
        actuation = mode(filament_model=model)
        key = repr(
            (pattern, n, ghosts, steps, actuation)
            + (
                ("bath floor", "buoyancy(T)", branch, lift_off_tolerance, path_check)
                if contact
                else ()
            )
        )
        extra: dict[str, Any] = {}
        if contact:
            from rotomorph.lattice.heating import lattice_buoyancy

            extra = {
                "floor": True,
                "gravity": lattice_buoyancy(lattice),
                "branch": branch,
                "lift_off_tolerance": lift_off_tolerance,
                "path_check": path_check,
            }
        result = disk_cached(
            "heat_lattice",
            key,
            lambda: heat_lattice(lattice, actuation=actuation, steps=steps, **extra),
        )
        return lattice, result, ""
    except RotomorphError as err:
        logger.warning("lattice %s: %s", pattern, err)
        return lattice, None, f"lattice solver failed: {' '.join(str(err).split())[:160]}"


def _area_sd(
    fit: Fit, pattern: str, quick: bool, ghosts: int, heat: Callable[..., Any] = _heat
) -> tuple[float | None, float | None]:
    """Calibration sd of a lattice's final area and the part of it the priors hold
    (one-sided secants, :data:`SD_STEPS` steps; :func:`sd_ramps` ramps)."""

    def area(m: FilamentModel) -> FloatArray:
        _, res, _ = heat(pattern, quick, SD_STEPS, at_resolution(m), ghosts)
        return np.array([np.nan if res is None else res.final_area_ratio])

    _, sd, sd_prior = fit.propagate_parts(area, central=False)
    if not np.isfinite(sd[0]):
        return None, None
    return float(sd[0]), float(sd_prior[0])


def _lattice_extrapolation(lattice: Any) -> list[str]:
    """Why a lattice's print settings lie outside the calibrated range (empty: inside)."""
    from rotomorph.materials.calibrated_range import calibrated_range

    if lattice is None:
        return []
    return calibrated_range().outside(
        speed=lattice.speeds,
        rotation_number=0.0,
        temperature=175.0,
        radius=float(lattice.radius),
        active_fraction=float(lattice.active_fraction),
    )


#: Why the lattice rows' bands are not split: the nuisance inputs are not propagated.
LATTICE_NUISANCE_NOTE = (
    "the inputs the paper does not give (cell size, filament width, densities, T_NI) are "
    "not propagated into this band (a Latin hypercube of contact-resolved ramps: "
    "benchmarks/lattice_nuisance.py), so it is not split and the row is neither a weak nor "
    "a discriminating test"
)


def _lift_off_statement(lattice: Any, lift: float, buckling: float) -> dict[str, Any]:
    """Lift-off and buckling relative to T_NI, and the buoyant density the weight delay
    follows from, with the assumptions (fields and a sentence for the note)."""
    from rotomorph.materials.bath import bath_density
    from rotomorph.materials.material import get_material

    active = get_material(lattice.active_material)
    passive = get_material(lattice.passive_material)
    t_ni = active.transition_temperature
    rho = 0.5 * (active.density + passive.density)
    rho_bath = bath_density(temperature=175.0)
    out: dict[str, Any] = {
        "transition_C": t_ni,
        "relative_to_transition_C": None if t_ni is None else round(lift - t_ni, 2),
        "buckling_relative_to_transition_C": None if t_ni is None else round(buckling - t_ni, 2),
        "delay_C": round(lift - buckling, 2),
        "buoyant_density_175C": round(rho - rho_bath, 4),
    }
    rel = (
        ""
        if t_ni is None
        else f"lift-off at T_NI {lift - t_ni:+.1f} °C and weightless buckling at T_NI "
        f"{buckling - t_ni:+.1f} °C, with T_NI = {t_ni:g} °C a placeholder (measured by DSC, "
        "not stated in the paper: every temperature here moves with it); "
    )
    out["statement"] = (
        rel + f"the buoyant weight delays lift-off by {lift - buckling:.1f} °C at "
        f"ρ − ρ_bath = {rho - rho_bath:.3f} g/cm³ at 175 °C (filament {rho:.3g} g/cm³, the "
        "inks' mean, and the silicone oil's table density, both assumed); the delay is the "
        "weight's (it vanishes with ρ − ρ_bath)"
    )
    return out


def sd_ramps(fit: Fit) -> int:
    """Ramps :func:`_area_sd` runs for one lattice: the centre and one per direction."""
    return 1 + sum(1 for d in fit.directions().T if np.any(d))


def lattice_computations(fit: Fit, quick: bool) -> int:
    """Lattice ramps :func:`_lattice_section` computes (or finds cached) in any case; a
    refinement or a resting-state ramp it finds necessary on the way adds one each."""
    if quick:
        return 4 + 2  # without contact, and the expanding and contracting ones finer
    # without contact; on the floor (4 coarse, 2 finer areas, 2 finer surfaces); the sd
    return 4 + 4 + 2 + 2 + 2 * sd_ramps(fit)


def _lattice_section(
    fit: Fit,
    figs: Path | None,
    *,
    quick: bool,
    steps: int,
    tick: Callable[[], None],
    grow: Callable[[int], None] = lambda n: None,
) -> tuple[list[dict], list[Path]]:
    """Lattice rows and, unless ``figs`` is None, their figures. ``tick()`` is called after
    every lattice ramp (:func:`lattice_computations` of them, and ``grow(1)`` first for each
    one more)."""

    def _counted(*args: Any, **kwargs: Any) -> tuple[Any, Any, str]:
        out = _heat(*args, **kwargs)
        tick()
        return out

    model = at_resolution(fit.model)
    from rotomorph.analysis.curvature import network_relative_curvature_change
    from rotomorph.plot.figure import new_figure, save_figure

    rows: list[dict] = []
    paths: list[Path] = []
    table = load_table("lattice_area")
    size = "3x3 (quick)" if quick else "5x5"
    results: dict[str, Any] = {}
    fine: dict[str, Any] = {}
    coarse_g, fine_g = LATTICE_GHOSTS[quick]
    for pattern in ("expanding", "contracting", "dome", "saddle"):
        results[pattern] = _counted(pattern, quick, steps, model, coarse_g)
        if quick and pattern in ("expanding", "contracting"):
            fine[pattern] = _counted(pattern, quick, steps, model, fine_g)[1]

    # contact-resolved ramps: self-contact, resting on the bath floor under buoyant weight.
    # These are the physical states, so the counted areas come from them (at two resolutions).
    # Left out in quick mode, whose 3 x 3 smoke run must stay fast: its rows come from the
    # ramps without contact and say so.
    paths_checked: dict[tuple[str, int], str] = {}

    def on_floor(pattern: str, ghosts: int) -> tuple[Any, Any, str]:
        lift_tol = LIFT_OFF_TOLERANCE if pattern in ("dome", "saddle") else None
        out = _counted(
            pattern,
            quick,
            steps,
            model,
            ghosts,
            True,
            lift_off_tolerance=lift_tol,
            path_check=PATH_CHECK_FACTOR,
        )
        if out[1] is not None and out[1].path_check is not None:
            paths_checked[pattern, ghosts] = out[1].path_check.note
        return out

    def path_note(pattern: str) -> str:
        return "; ".join(
            f"{g} ghost nodes per edge, {paths_checked[pattern, g]}"
            for g in (coarse_g, fine_g, 2 * fine_g)
            if (pattern, g) in paths_checked
        )

    resolved = (
        {}
        if quick
        else {p: on_floor(p, coarse_g) for p in ("expanding", "contracting", "dome", "saddle")}
    )
    if not quick:
        for pattern in ("expanding", "contracting"):
            fine[pattern] = on_floor(pattern, fine_g)[1]
    # a counted area not converged to 1 % between the two resolutions is refined once more
    # (twice the finer ghost count) and counted there, with the finer of the first pair as
    # its convergence check
    pairs: dict[str, tuple[int, int, float | None]] = {}
    for pattern in ("expanding", "contracting"):
        lo_res = results[pattern][1] if quick else resolved[pattern][1]
        hi_res = fine[pattern]
        pairs[pattern] = (
            coarse_g,
            fine_g,
            None if lo_res is None else float(lo_res.final_area_ratio),
        )
        if quick or lo_res is None or hi_res is None:
            continue
        a_lo, a_hi = float(lo_res.final_area_ratio), float(hi_res.final_area_ratio)
        if abs(a_hi - a_lo) > CONVERGENCE_RTOL * abs(a_hi):
            grow(1)
            finer = on_floor(pattern, 2 * fine_g)[1]
            if finer is not None:
                fine[pattern] = finer
                pairs[pattern] = (fine_g, 2 * fine_g, a_hi)
    # dome and saddle at the finer resolution too: their counted sign, curvature and lift-off
    # come from it, the coarser one is the convergence check
    surfaces = {} if quick else {p: on_floor(p, fine_g) for p in ("dome", "saddle")}
    # Fig. 3G: area
    fig = new_figure(6.0, 4.2)
    ax = fig.add_subplot()
    for i, pattern in enumerate(("expanding", "contracting")):
        lattice, res, why = results[pattern]
        touched = resolved.get(pattern, (None, None, ""))[1]
        measured = 1.0 + float(table.value[i]) / 100.0
        spread = float(table.spread[i]) / 100.0
        if quick:
            how = (
                f"quick mode: no contact (min clearance {np.min(res.min_clearance):.2f} diameters)"
                if res is not None
                else ""
            )
        else:
            counted_g = pairs[pattern][1]
            shown = fine[pattern]
            how = (
                f"at {counted_g} ghost nodes per edge: self-contact (centre lines never closer "
                f"than a diameter: min clearance {np.min(shown.min_clearance):.3f}) and the "
                f"bath floor under buoyant weight; {int(shown.contacts_active[-1])} contacts at "
                f"{shown.parameter[-1]:.0f} °C; largest rise off the floor "
                f"{float(shown.floor_lift[-1]):.2f} mm"
                + (
                    ""
                    if shown.first_lift_off() is None
                    else f" (left the floor at {shown.first_lift_off():.4g} °C: the lifted "
                    "equilibrium is lower in energy than the resting one)"
                )
                + "; "
                + path_note(pattern)
                if shown is not None
                else ""
            )
        counted_state = fine[pattern]
        end_ok, end_reason = _end_physical(res if quick else counted_state)
        physical = (
            (res is not None and float(np.min(res.min_clearance)) >= 1.0)
            if quick
            else counted_state is not None and float(np.min(counted_state.min_clearance)) >= 0.999
        ) and end_ok
        cal, cal_prior = (
            (None, None)
            if quick or res is None
            else _area_sd(fit, pattern, quick, coarse_g, _counted)
        )
        main_row = _row(
            "lattice_area_ratio",
            table.condition[i],
            measured,
            spread,
            None if counted_state is None else counted_state.final_area_ratio,
            predicted_sd=cal,
            other=pairs[pattern][2],
            resolution=pairs[pattern][:2],
            resolution_unit="ghost nodes per edge",
            calibrated_without="lattice_area (never fitted); A/l = 0.25 from the authors' "
            "published simulation input; the cell size (5 mm) is the package's default, not "
            "given in the paper",
            counted=None if physical else False,
            unit="1",
            figure="fig3g_lattice_area.png",
            note=why
            or f"{size} lattice (cell 5 mm, A = 1.25 mm, filament width 0.6 mm: assumed; "
            "below the cell-size prior of 6.3-9.2 mm the printed openings of Fig. 5 give) "
            f"heated {res.parameter[0]:.0f} → {res.parameter[-1]:.0f} °C through the "
            f"calibrated materials chain ('{res.actuation}'); calibration sd by one-sided "
            f"secants at {coarse_g} ghost nodes without contact ({SD_STEPS} steps; none in "
            f"quick mode); {LATTICE_NUISANCE_NOTE}; measured A/A0 = 1 + change (%)/100; {how}",
            physical=physical,
            physical_reason=end_reason,
        )
        main_index = len(rows)
        rows.append(main_row)
        lifted = None if touched is None else touched.first_lift_off()
        resting = None
        if not quick and lifted is not None:
            grow(1)
            _, resting, why_r = _counted(
                pattern,
                quick,
                steps,
                model,
                coarse_g,
                True,
                "continuous",
                path_check=PATH_CHECK_FACTOR,
            )
            rows.append(
                _row(
                    "lattice_area_ratio",
                    f"{table.condition[i]}, kept on the floor",
                    measured,
                    spread,
                    None if resting is None else float(resting.final_area_ratio),
                    counted=False,
                    unit="1",
                    figure="fig3g_lattice_area.png",
                    note=why_r
                    or f"{size}; the same contact ramp following the resting state "
                    "continuously (a metastable equilibrium on the floor: lifting costs "
                    "weight × height to first order), where the counted row takes the "
                    f"lifted equilibrium of lower energy from {lifted:.4g} °C on; largest "
                    f"rise {float(resting.floor_lift[-1]):.2f} mm, "
                    f"{int(resting.contacts_active[-1])} contacts; "
                    + ("" if resting.path_check is None else resting.path_check.note),
                    physical=_end_physical(resting)[0],
                    physical_reason=_end_physical(resting)[1],
                )
            )
        # two branches (lifted or kept jammed on the floor) the data do not choose between:
        # half their difference is the model-form part of the band
        model_form = (
            0.5 * abs(float(touched.final_area_ratio) - float(resting.final_area_ratio))
            if touched is not None and resting is not None
            else 0.0
        )
        rows[main_index] = finish_row(
            main_row,
            Band(
                calibration=cal,
                calibration_prior=cal_prior,
                nuisance=None,
                numerical=main_row["discretisation_error"],
                model_form=model_form,
            ),
            extrapolated=_lattice_extrapolation(lattice),
        )
        if not quick and res is not None:
            clearance = float(np.min(res.min_clearance))
            overlap = clearance < 1.0
            rows.append(
                _row(
                    "lattice_area_ratio",
                    f"{table.condition[i]}, without contact",
                    measured,
                    spread,
                    float(res.final_area_ratio),
                    counted=False,
                    unit="1",
                    figure="fig3g_lattice_area.png",
                    note=f"{size}; the same ramp without a contact model: min clearance "
                    f"{clearance:.2f} diameters"
                    + (
                        "; filaments pass through each other, not a physical state"
                        if overlap
                        else ""
                    ),
                    physical=not overlap and _end_physical(res)[0],
                    physical_reason="; ".join(
                        w
                        for w in ("filaments overlap" if overlap else "", _end_physical(res)[1])
                        if w
                    ),
                )
            )
        if res is not None:
            ax.plot(res.parameter, res.area_ratio, "o-", ms=3, label=f"{pattern} (no contact)")
        if touched is not None:
            ax.plot(touched.parameter, touched.area_ratio, "s-", ms=3,
                    label=f"{pattern} (contact, on the floor)")  # fmt: skip
        if resting is not None:
            ax.plot(resting.parameter, resting.area_ratio, "s--", ms=3, mfc="none",
                    label=f"{pattern} (contact, kept on the floor)")  # fmt: skip
        x_end = 0.75 if res is None else float(res.parameter[-1])
        ax.errorbar([x_end], [measured], yerr=[spread], fmt="s", capsize=3,
                    label=f"{pattern} (measured, 175 °C)")  # fmt: skip
    ax.set_xlabel("ramp parameter: temperature (°C)")
    ax.set_ylabel("A/A0 (–)")
    counted_ends = [
        results[p][1] if quick else fine[p] for p in ("expanding", "contracting")
    ]  # the states the area rows count
    bad = [
        (p, _end_physical(r)[1])
        for p, r in zip(("expanding", "contracting"), counted_ends, strict=True)
        if not _end_physical(r)[0]
    ]
    ax.set_title(
        "Fig. 3G: lattice area on heating"
        + "".join(f"\nNOT PHYSICAL ({p}): {why}" for p, why in bad),
        color="tab:red" if bad else "k",
        fontsize=10 if bad else None,
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    if figs is not None:
        paths.append(save_figure(fig, figs / "fig3g_lattice_area.png"))
    # Fig. 3E/F and Fig. 4A/D: views coloured by (κ − κ_i)/κ_i at the end of the ramp,
    # contact-resolved where filaments touch
    for pattern in ("expanding", "contracting", "dome", "saddle"):
        lattice, res, _ = surfaces.get(pattern, resolved.get(pattern, results[pattern]))
        if res is None or figs is None:
            continue
        k = len(res.parameter) - 1
        rel = network_relative_curvature_change(
            res.positions[k], res.positions[0], lattice.edge_chains
        )
        state = (
            "contact-resolved, on the bath floor"
            if res.contact is not None
            else f"no contact needed: clearance {np.min(res.min_clearance):.2f} diameters"
        )
        title, colour = _flagged(f"{pattern} lattice, {res.parameter[k]:.3g} °C ({state})", res)
        f = lattice_tube_figure(lattice, res, rel, title=title, title_colour=colour)
        paths.append(save_figure(f, figs / f"lattice_{pattern}_views.png"))
    # Fig. 4C/F: sign and characteristic curvature vs strain
    fig = new_figure(10.0, 5.0)
    axes = fig.subplots(1, 2)
    for ax, (pattern, sign, panel) in zip(
        axes, (("dome", 1, "4C"), ("saddle", -1, "4F")), strict=True
    ):
        coarse = resolved.get(pattern, results[pattern])[1]
        lattice, res, why = surfaces.get(pattern, resolved.get(pattern, results[pattern]))
        other = None if coarse is None or coarse is res else coarse
        check: dict[str, Any] = (
            {}
            if other is None
            else {"resolution": (coarse_g, fine_g), "resolution_unit": "ghost nodes per edge"}
        )
        sign_row = _row(
            "lattice_gaussian_sign",
            f"{pattern} lattice",
            float(sign),
            0.0,
            None if res is None else float(res.gaussian_sign[-1]),
            counted=res is not None,
            other=None if other is None else float(other.gaussian_sign[-1]),
            **check,
            calibrated_without="lattice (never fitted)",
            unit="1",
            figure="fig4cf_characteristic_curvature.png",
            physical=_end_physical(res)[0],
            physical_reason=_end_physical(res)[1],
            surface=None if res is None else _surface_record(lattice, res),
            note=why
            or f"{size}; sign of the fitted Gaussian curvature of the branch nodes at the "
            f"end of the ramp ({res.parameter[-1]:.4g}), "
            + (
                "contact-resolved on the bath floor under buoyant weight (min clearance "
                f"{np.min(res.min_clearance):.3f}); first rises one diameter off the floor "
                f"at {res.first_lift_off()}; {path_note(pattern)}"
                if res.contact is not None
                else "quick mode: no contact (min clearance "
                f"{np.min(res.min_clearance):.2f} diameters)"
            )
            + f"; read as a surface: {_surface_text(lattice, res)}; {LATTICE_NUISANCE_NOTE}",
        )
        rows.append(
            finish_row(
                sign_row,
                Band(),
                extrapolated=_lattice_extrapolation(lattice),
            )
        )
        rows.append(
            _row(
                "lattice_characteristic_curvature",
                f"{pattern} lattice, final",
                None,
                None,
                None if res is None else float(res.characteristic_curvature[-1]),
                other=None if other is None else float(other.characteristic_curvature[-1]),
                **check,
                unit="1/mm",
                figure="fig4cf_characteristic_curvature.png",
                physical=_end_physical(res)[0],
                physical_reason=_end_physical(res)[1],
                note=why
                or "√|k₁k₂| of the branch-node surface fit at mean edge strain "
                f"{res.mean_edge_strain[-1]:+.3f}; the paper gives this only as a plot",
            )
        )
        if res is not None and getattr(res, "lift_off_bracket", None) is not None:
            lo, hi = res.lift_off_bracket
            b_lo, b_hi = res.buckling_bracket or (np.nan, np.nan)
            o_br = None if other is None else other.lift_off_bracket
            o_mid = None if o_br is None else 0.5 * (o_br[0] + o_br[1])
            stated = _lift_off_statement(lattice, 0.5 * (lo + hi), 0.5 * (b_lo + b_hi))
            rows.append(
                _row(
                    "lattice_lift_off_temperature",
                    f"{pattern} lattice on the bath floor",
                    None,
                    None,
                    round(0.5 * (lo + hi), 2),
                    other=o_mid,
                    disc_error=max(
                        0.5 * (hi - lo), 0.0 if o_mid is None else abs(o_mid - 0.5 * (lo + hi))
                    ),
                    **check,
                    unit="°C",
                    figure="fig4cf_characteristic_curvature.png",
                    note=f"{size}; {stated['statement']}; lift-off: the first temperature at "
                    "which a lifted equilibrium is lower in total energy than the lattice "
                    f"resting flat under its buoyant weight, bisected to [{lo:.2f}, {hi:.2f}] "
                    f"°C; the weightless flat lattice buckles at [{b_lo:.2f}, {b_hi:.2f}] °C "
                    "(the paper: a finite delay, larger for the saddle; no number given)"
                    + (
                        "; on the counted path (the sub-stepped ramp, lower in end energy): "
                        "the ramp as requested ends in another state and leaves the floor at "
                        "another temperature"
                        if res.path_check is not None and res.path_check.kept == "sub-steps"
                        else ""
                    ),
                    **{k: v for k, v in stated.items() if k != "statement"},
                )
            )
        if res is not None:
            ax.plot(res.mean_edge_strain, res.characteristic_curvature, "ko-", ms=3,
                    label="simulation (one point per ramp step)")  # fmt: skip
            lift = res.first_lift_off()
            if lift is not None:
                k = int(np.flatnonzero(res.parameter == lift)[0])
                ax.plot(
                    res.mean_edge_strain[k],
                    res.characteristic_curvature[k],
                    "o",
                    ms=9,
                    mfc="none",
                    mec="tab:red",
                    label=f"first ramp step off the floor ({lift:.4g} °C)"
                    + (
                        ""
                        if res.lift_off_bracket is None
                        else f"; lift-off bisected to {0.5 * sum(res.lift_off_bracket):.1f} °C"
                    ),
                )
        ax.set_xlabel("mean edge strain (–)")
        ax.set_ylabel("characteristic curvature √|k₁k₂| (1/mm)")
        got = "" if res is None else f", simulated sign {int(res.gaussian_sign[-1]):+d}"
        title, colour = _flagged(
            f"Fig. {panel}: {pattern} pattern (paper: κ_g {'>' if sign > 0 else '<'} 0{got})", res
        )
        ax.set_title(title, fontsize=10, color=colour)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.16))
    fig.subplots_adjust(bottom=0.3, wspace=0.3)  # legends below the axes, clear of the data
    if figs is not None:
        paths.append(save_figure(fig, figs / "fig4cf_characteristic_curvature.png"))
    return rows, paths


def paper_rows(*, quick: bool = False) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The report's rows and score without writing anything (no figures).

    Parameters
    ----------
    quick
        3 × 3 lattices with 3 heating steps (the filament rows do not change).

    Returns
    -------
    rows, summary
        Exactly the rows of ``summary.json`` and :func:`summarise` of them.
    """
    val = validate_filaments()
    rows = _ordered(val, lattice_rows(quick=quick))
    return rows, summarise(rows)


def lattice_rows(*, quick: bool = False) -> list[dict[str, Any]]:
    """The report's lattice rows (areas, contact-resolved areas, signs) without figures.

    Each lattice is heated through the model calibrated on all filament groups, every printed
    line driven by its own print program; ``quick``: 3 × 3 lattices, 3 steps, no sd.
    """
    val = validate_filaments()
    rows, _ = _lattice_section(
        val.calibrations["all"].chosen,
        None,
        quick=quick,
        steps=3 if quick else LATTICE_STEPS,
        tick=lambda: None,
    )
    return rows


def _ordered(val: Validation, lattice: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """Rows in report order: filament groups, sinusoids, lattices, inputs."""
    order = (
        "janus_curvature",
        "pure_lce_length_L_over_L0",
        "composite_length_L_over_L0",
        "sinusoid_end_to_end_ratio",
    )
    rows = [r for q in order for r in val.rows if r["quantity"] == q]
    rows += lattice
    rows += [r for r in val.rows if r["quantity"] in ("order_parameter", "normalized_length")]
    # every row carries the band fields (rows without a computed band: not computed)
    return [r if "weak_test" in r else plain_row(r) for r in rows]


# ----------------------------------------------------------------------------- report


def _fmt(v: Any) -> str:
    if v is None:
        return "—"
    if isinstance(v, bool):
        return "yes" if v else ""
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


def _table_cell(text: str) -> str:
    """``text`` as one cell of a Markdown table: a ``|`` in it (as in √|k₁k₂|) is escaped, so
    it renders as itself instead of splitting the cell."""
    return str(text).replace("|", "\\|")


def _markdown(
    rows: list[dict],
    figures: list[Path],
    val: Validation,
    summary: dict[str, Any],
    timings: dict,
    quick: bool,
    extra: list[str] | None = None,
) -> str:
    full = val.calibrations["all"]
    fit = full.chosen
    params = ", ".join(
        f"`{k}` = {v:.4g} (±1 sd: {lo:.3g}–{hi:.3g})"
        for (k, v), (lo, hi) in zip(fit.values.items(), fit.intervals.values(), strict=True)
    )
    lines = [
        "# rotomorph: the paper's measurements, predicted out of sample",
        "",
        f"rotomorph {rotomorph.__version__}{' — quick mode (coarse; for tests)' if quick else ''}."
        " Spreads are the paper's s.d. (n = 3); `z` = (predicted − measured) / √(spread² + "
        "predicted_sd²).",
        "",
        f"**{summary_line(summary)}.**",
        "",
        "## Calibration",
        "",
        "Joint weighted fit (with weak stated priors) of E_a/E_p at actuation, the threshold "
        "strain law's gain and S0 and the passive strain to the Janus curvature vs speed, the "
        "pure-LCE and the composite L/L0 vs ω*. Each of these groups is predicted by the fit "
        "to the other two; sinusoids and lattices are never fitted. All filament groups: "
        + params
        + f"; χ² = {fit.chi2_data:.2f} for {fit.n_data} points.",
        "",
        "Both modulus-ratio branches (bilayer curvature is symmetric under E_a/E_p ↔ E_p/E_a):",
        "",
    ]
    for name, cal in val.calibrations.items():
        for b in cal.branches:
            lines.append(
                f"- {name}, {b.label}: "
                + ", ".join(f"{k} = {v:.4g}" for k, v in b.values.items())
                + f"; χ² = {b.chi2_data:.2f}"
                + (f"; on the bound ({', '.join(b.at_bound)})" if b.at_bound else "")
            )
        lines.append(f"  - chosen: {cal.chosen.label} — {cal.choice}")
    lines += ["", "Full record: `calibration.json`.", ""]
    lines += _priors_section()
    sections = [
        ("Fig. 2D — Janus curvature vs print speed", ("janus_curvature",)),
        (
            "Fig. 2F/G — L/L0 vs ω*",
            ("pure_lce_length_L_over_L0", "composite_length_L_over_L0"),
        ),
        ("Fig. 3C/D — sinusoidal filaments", ("sinusoid_end_to_end_ratio",)),
        ("Fig. 3G — lattice area", ("lattice_area_ratio",)),
        (
            "Fig. 4 — dome and saddle lattices",
            (
                "lattice_gaussian_sign",
                "lattice_characteristic_curvature",
                "lattice_lift_off_temperature",
            ),
        ),
        ("Inputs (measured values the model takes as given)", ("order_parameter",
                                                                "normalized_length")),
    ]  # fmt: skip
    names = {p.name for p in figures}
    for title, quantities in sections:
        sel = [r for r in rows if r["quantity"] in quantities]
        lines += [f"## {title}", ""]
        lines += [
            "| quantity | condition | measured | ± | predicted | ± sd | sd: calibration / "
            "nuisance / numerical | z | test | fit/input | converged (error) | note |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |",
        ]
        for r in sel:
            conv = "yes" if r["converged"] else "**NO**"
            if r["discretisation_error"] is not None:
                conv += f" ({r['discretisation_error']:.2g})"
            predicted = _fmt(r["predicted"])
            if r.get("physical") is False:
                predicted += " **NOT PHYSICAL**"
            cells = [
                r["quantity"],
                r["condition"],
                _fmt(r["measured"]),
                _fmt(r["spread"]),
                predicted,
                _fmt(r["predicted_sd"]),
                _parts(r),
                _fmt(r["z"]),
                _test(r),
                _fmt(r["calibration"]),
                conv if r["predicted"] is not None else "—",
                (
                    "EXTRAPOLATED: " + "; ".join(r["extrapolation"]) + ". "
                    if r.get("extrapolated")
                    else ""
                )
                + r["note"],
            ]
            lines.append("| " + " | ".join(map(_table_cell, cells)) + " |")
        lines.append("")
        for fig in dict.fromkeys(r["figure"] for r in sel):
            if fig in names:
                lines += [f"![{fig}](figures/{fig})", ""]
        if quantities[0] == "pure_lce_length_L_over_L0" and "fig2fg_shapes.png" in names:
            lines += ["![shapes](figures/fig2fg_shapes.png)", ""]
        if quantities[0] == "lattice_gaussian_sign":
            lines += [
                "Views at the end of the ramp: every lattice with self-contact, resting on the "
                "bath floor under its buoyant weight (filaments never pass through each "
                "other).",
                "",
            ]
            for pattern in ("expanding", "contracting", "dome", "saddle"):
                for suffix in ("", "_final"):
                    name = f"lattice_{pattern}_views{suffix}.png"
                    if name in names:
                        lines += [f"![{pattern}{suffix}](figures/{name})", ""]
    lines += extra or []
    if summary["misses_beyond_2"]:
        lines += ["## Misses beyond 2 combined spreads", ""]
        lines += [f"- {m}" for m in summary["misses_beyond_2"]] + [""]
    if summary["not_converged"]:
        lines += ["## NOT converged to 1 %", ""]
        lines += [f"- {m}" for m in summary["not_converged"]] + [""]
    unphysical = [r for r in rows if r.get("physical") is False and r["predicted"] is not None]
    if unphysical:
        lines += ["## NOT PHYSICAL", ""]
        lines += [
            f"- {r['quantity']}, {r['condition']}: {r.get('physical_reason') or 'not physical'}"
            for r in unphysical
        ] + [""]
    lines += [
        "## Timings",
        "",
        *[f"- {k}: {v:.1f} s" for k, v in timings.items()],
        "",
    ]
    return "\n".join(lines)


def _priors_section() -> list[str]:
    """Markdown: the nuisance priors and the weak-test rule."""
    lines = [
        "## Inputs the paper does not give (nuisance priors)",
        "",
        "Predictions are made at the centres of these uniform priors; each row's band carries "
        "them through a Latin hypercube (`sd_nuisance`). Ranges and arguments were stated "
        "before any prediction used them.",
        "",
        "| input | range | nominal | unit | source or argument |",
        "| --- | --- | --- | --- | --- |",
    ]
    for p in priors_record():
        lo, hi = p["range"]
        lines.append(
            f"| {p['name']} | {lo:g}-{hi:g} | {p['nominal']:.4g} | {p['unit']} | {p['source']} |"
        )
    lines += ["", f"**Weak tests.** {WEAK_RULE}", ""]
    return lines


def _published(out: Path, figs: Path, quick: bool) -> tuple[list[str], list[Path]]:
    """The section on the authors' own Fig. 4 simulation (Markdown lines, figures); a failed
    sweep becomes a section that says why."""
    from rotomorph.simulate.report_published import published_section

    try:
        section = published_section(out, figs, quick=quick)
    except RotomorphError as err:
        logger.warning("authors' Fig. 4 simulation: %s", err)
        why = " ".join(str(err).split())[:300]
        return [
            "## The authors' own simulation of Fig. 4 (disMech), rebuilt",
            "",
            f"**Not computed**: the sweep failed ({why}).",
            "",
        ], []
    return section.lines, section.figures


#: Markers around the generated prediction table in README.md.
TABLE_START = "<!-- prediction-table: generated by rotomorph paper (prediction_table.md) -->"
TABLE_END = "<!-- prediction-table: end -->"


def _pm(value: Any, sd: Any, digits: int = 3) -> str:
    if value is None:
        return "—"
    text = f"{value:.{digits}g}"
    return text if not sd else f"{text} ± {sd:.2g}"


def _parts(r: dict[str, Any]) -> str:
    """``0.012 / 0.034 / 0.002`` (calibration / nuisance / numerical; model form appended)."""
    keys = ("sd_calibration", "sd_nuisance", "sd_numerical")
    if r["predicted"] is None or all(r.get(k) is None for k in keys):
        return "—"
    text = " / ".join("—" if r.get(k) is None else f"{r[k]:.2g}" for k in keys)
    if r.get("sd_model_form"):
        text += f" (+ branch {r['sd_model_form']:.2g})"
    return text


def _test(r: dict[str, Any]) -> str:
    if r["calibration"] or not r["counted"]:
        return "—"
    if r.get("weak_test") is None:
        return "band not split"
    return "weak" if r["weak_test"] else "discriminating"


def prediction_table(rows: list[dict[str, Any]], summary: dict[str, Any]) -> str:
    """The README's prediction table (Markdown) from the summary rows, with the score line.

    One line per measured quantity: the prediction with its band (± its total), the band's
    calibration / nuisance / numerical parts (:mod:`rotomorph.simulate.bands`), ``z``, whether
    the comparison is a weak test or discriminates, and how it was made (``fit/input``: not a
    prediction; ``EXTRAPOLATED``: outside the calibrated range).
    """
    lines = [
        TABLE_START,
        "",
        "| quantity | condition | measured | predicted (± sd) | sd: calibration / nuisance / "
        "numerical | z | test | how |",
        "| --- | --- | --- | --- | --- | --- | --- | --- |",
    ]
    for r in rows:
        if r["measured"] is None:
            continue
        if r["calibration"]:
            how = "input / fit"
        elif r["counted"]:
            how = "out of sample"
        elif r.get("informed_by"):
            how = f"not counted ({r['informed_by']})"
        else:
            how = "not counted"
        if r["predicted"] is not None and not r["converged"]:
            how += ", NOT converged"
        if r.get("physical") is False:
            how += f", NOT PHYSICAL ({r.get('physical_reason') or 'filaments overlap'})"
        if r.get("extrapolated"):
            how += ", EXTRAPOLATED"
        z = "—" if r["z"] is None else f"{r['z']:+.1f}"
        lines.append(
            f"| {r['quantity']} | {r['condition']} | {_pm(r['measured'], r['spread'])} | "
            f"{_pm(r['predicted'], r['predicted_sd'])} | {_parts(r)} | {z} | {_test(r)} | "
            f"{how} |"
        )
    lines += ["", f"{summary_line(summary)}.", "", TABLE_END]
    return "\n".join(lines)


def paper_report(
    folder: str | Path,
    *,
    quick: bool = False,
    progress: Progress | None = None,
    allow_unconverged: bool = True,
) -> PaperReport:
    """Predict the paper's measurements out of sample and write the report into ``folder``.

    Parameters
    ----------
    folder
        Output folder (must exist); ``figures/`` is created in it.
    quick
        3 × 3 lattices with 3 heating steps (for tests); the filament numbers are the same.
    progress
        Called as ``progress(done, total)`` with the units finished since the last call
        and the units planned so far: the calibrations, three filament sections, the authors'
        Fig. 4 sweeps and every lattice ramp (:func:`lattice_computations`; a refinement found
        necessary on the way raises ``total`` by one).
    allow_unconverged
        When false, raise :class:`~rotomorph.errors.ConvergenceError` (after writing the
        report) if a reported number is not converged to 1 % between its two resolutions.

    Returns
    -------
    PaperReport
    """
    t0 = time.perf_counter()
    out = Path(folder)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    lattice_steps = 3 if quick else LATTICE_STEPS
    # calibrations, three filament sections and the authors' Fig. 4 sweeps; then the
    # lattice ramps
    plan = {"total": 5}

    def tick() -> None:
        if progress is not None:
            progress(1, plan["total"])

    def grow(n: int) -> None:
        plan["total"] += n

    timings: dict[str, float] = {}
    if progress is not None:  # the plan so far shows from the start, not a bare count
        progress(0, plan["total"])
    phase_log.info("calibrations and filament predictions", extra={"task": True})
    val = validate_filaments()
    fit = val.calibrations["all"].chosen
    grow(lattice_computations(fit, quick))
    timings["calibrations and filament predictions"] = time.perf_counter() - t0
    tick()
    rows: list[dict] = []
    figures: list[Path] = []
    for name, section in (
        ("Fig. 2D", lambda: _curvature_section(val, figs)),
        ("Fig. 2F/G", lambda: _rotation_section(val, figs)),
        ("Fig. 3C/D", lambda: _sinusoid_section(val, figs)),
        (
            "lattices (Fig. 3G, 4)",
            lambda: _lattice_section(
                fit, figs, quick=quick, steps=lattice_steps, tick=tick, grow=grow
            ),
        ),
    ):
        phase_log.info("%s", name, extra={"task": True})
        t = time.perf_counter()
        r, f = section()
        rows += r
        figures += f
        timings[name] = time.perf_counter() - t
        if name != "lattices (Fig. 3G, 4)":
            tick()
    t = time.perf_counter()
    phase_log.info("authors' Fig. 4 simulation rebuilt (two stretch sweeps)", extra={"task": True})
    published = _published(out, figs, quick)
    figures += published[1]
    timings["authors' Fig. 4 simulation rebuilt (two stretch sweeps)"] = time.perf_counter() - t
    tick()
    rows = _ordered(val, [r for r in rows if r["quantity"].startswith("lattice")])
    summary = summarise(rows)
    wall = time.perf_counter() - t0
    timings["total"] = wall
    write_summary(out / "summary.json", rows)  # type: ignore[arg-type]
    record = {
        "summary": summary,
        "summary_line": summary_line(summary),
        "calibrations": {k: c.record() for k, c in val.calibrations.items()},
        "nuisance_priors": priors_record(),
        "weak_test_rule": WEAK_RULE,
    }
    atomic_write_text(out / "calibration.json", json.dumps(record, indent=1))
    atomic_write_text(
        out / "report.md", _markdown(rows, figures, val, summary, timings, quick, published[0])
    )
    atomic_write_text(out / "prediction_table.md", prediction_table(rows, summary) + "\n")
    if summary["not_converged"] and not allow_unconverged:
        raise ConvergenceError(
            "paper report: not converged to 1 % between the two resolutions: "
            + "; ".join(summary["not_converged"])
        )
    return PaperReport(
        rows=rows,
        figures=figures,
        parameters=val.calibrations["all"].chosen.values,
        wall_time=wall,
        timings=timings,
        summary=summary,
    )
