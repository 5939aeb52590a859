"""Run an inverse design from a target file: design, verification, design file, figures, summary.

:func:`run_inverse` returns an :class:`InverseRun` (the printable design as a design-file model
that ``rotomorph validate``, ``simulate`` and ``gcode`` accept unchanged, the verification
numbers and a convergence log); :func:`write_inverse` writes the design file and, in a folder
beside it, ``summary.json``, ``convergence.csv`` and the figures.
"""

from __future__ import annotations

import csv
import io
import json
import logging
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.inverse.bath import bath_contact
from rotomorph.inverse.environment import design_in_bath
from rotomorph.inverse.filament import FilamentDesign, design_filament
from rotomorph.inverse.lattice import LatticeDesign
from rotomorph.inverse.response import cached_response_table
from rotomorph.inverse.simplify import (
    CONVENTION,
    ROTATION_STEP,
    SPEED_STEP,
    SimpleProgram,
    simplest_program,
)
from rotomorph.inverse.targets import TargetFile, curve_points
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.design_limits import nozzle_table
from rotomorph.io.designfile import ContactModel, Design, parse_design, save_design
from rotomorph.simulate.surroundings import surroundings_record

#: What the inverse design is doing, for the command line's progress display.
phase_log = logging.getLogger("rotomorph.progress")

__all__ = [
    "InverseRun",
    "filament_design_file",
    "inverse_file",
    "lattice_design_file",
    "run_inverse",
    "write_inverse",
]


@dataclass(frozen=True, eq=False)
class InverseRun:
    """Outcome of an inverse design run.

    Attributes
    ----------
    target
        The validated target file.
    design
        The printable design (a validated design-file model).
    summary
        JSON-ready numbers: target and achieved metrics, errors, reachability, settings.
    log
        Convergence log rows ``(iteration, objective)``.
    result
        The :class:`FilamentDesign` (the per-vertex solution) or :class:`LatticeDesign`.
    program
        Filaments: the printed design, the simplest one within the target's tolerance
        (:class:`~rotomorph.inverse.simplify.SimpleProgram`); ``design`` is its file.
    """

    target: TargetFile
    design: Design
    summary: dict[str, Any]
    log: list[tuple[int, float]] = field(default_factory=list)
    result: FilamentDesign | LatticeDesign | None = None
    program: SimpleProgram | None = None


def _groups(values: FloatArray, tol: FloatArray) -> list[tuple[int, int]]:
    """Runs ``[start, end)`` of consecutive rows of ``values`` equal within ``tol``."""
    out = []
    i = 0
    while i < len(values):
        j = i + 1
        while j < len(values) and np.all(np.abs(values[j] - values[i]) <= tol):
            j += 1
        out.append((i, j))
        i = j
    return out


def _inks_entry(target: TargetFile | None) -> dict[str, Any]:
    """The design file's materials entry (the target's materials file, as an absolute path
    that :func:`write_inverse` makes relative to the design) and ink names."""
    if target is None or target.material_set is None:
        return {}
    return {"materials": str(Path(target.material_set.source).resolve())}


def _ink_names(target: TargetFile | None) -> dict[str, str]:
    if target is None or target.material_set is None:
        return {}
    return {
        "active_material": target.options.active_material,
        "passive_material": target.options.passive_material,
    }


def filament_design_file(
    design: FilamentDesign, name: str = "inverse", target: TargetFile | None = None
) -> Design:
    """The design file of a designed filament: line segments of constant speed and rotation.

    Each segment carries the speed of its moves and the rotation number that turns the nozzle
    by exactly the program's nozzle-angle change over it, so the file reproduces the program.
    """
    prog = design.program
    pts = np.asarray(prog.points)
    seg_len = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    d_angle = np.diff(np.asarray(prog.nozzle_angle))
    rate = d_angle / seg_len  # nozzle-angle change per printed length (rad/mm)
    speed = np.asarray(prog.speed)[:-1]
    rows = np.stack([speed, rate], axis=1)
    tol = np.array([1e-6 * max(float(np.max(speed)), 1.0), 1e-9 + 1e-6 * np.max(np.abs(rate))])
    segments = []
    for a, b in _groups(rows, tol):
        length = float(seg_len[a:b].sum())
        value = float(d_angle[a:b].sum() * prog.radius / length)
        segments.append(
            {
                "kind": "line",
                "length": length,
                "speed": float(np.mean(speed[a:b])),
                "rotation_number": value,
            }
        )
    spacing = float(np.max(seg_len)) * (1.0 + 1e-6)
    data = {
        "schema_version": 1,
        "name": name,
        "description": "designed by rotomorph inverse (straight print path; heats into the target)",
        "filaments": [
            {
                "name": name,
                "speed": float(speed[0]),
                "spacing": spacing,
                "radius": float(prog.radius),
                "active_fraction": float(prog.active_fraction),
                "initial_nozzle_angle_deg": math.degrees(float(prog.nozzle_angle[0])),
                "segments": segments,
                **_ink_names(target),
            }
        ],
        **_inks_entry(target),
    }
    data.update(nozzle_table(float(prog.radius)))  # when the default nozzle cannot print it
    return parse_design(data, materials=None if target is None else target.material_set)


def lattice_design_file(
    design: LatticeDesign,
    name: str = "inverse",
    contact: ContactModel | None = None,
    target: TargetFile | None = None,
) -> Design:
    """The design file of a designed lattice (``pattern = "custom"`` with per-edge modes and,
    where the design chose them, per-edge speeds), with the ``[contact]`` table it was designed
    with (so that ``rotomorph simulate`` verifies the same physics)."""
    lat = design.lattice
    data = {
        "schema_version": 1,
        "name": name,
        "description": f"designed by rotomorph inverse for {design.target.description}",
        "lattice": {
            "n": lat.n,
            "spacing": lat.spacing,
            "amplitude": lat.amplitude,
            "ghost_nodes": lat.ghost_nodes,
            "pattern": "custom",
            "edge_modes": ["expanding" if m > 0 else "contracting" for m in design.modes],
            "speed": lat.speed,
            # printed away from the machine's origin, as the example lattices are
            "origin": [20.0, 20.0, 0.0],
            **_ink_names(target),
            **(
                {}
                if lat.edge_speeds is None
                else {"edge_speeds": [round(v, 6) for v in lat.edge_speeds]}
            ),
        },
        **({} if contact is None else {"contact": contact.model_dump()}),
        **_inks_entry(target),
    }
    return parse_design(data, materials=None if target is None else target.material_set)


def run_inverse(
    target: TargetFile, progress: Callable[[int, float], None] | None = None
) -> InverseRun:
    """Design, verify and package the print program for a target (module docstring)."""
    opt = target.options
    name = target.name or target.kind
    if target.kind == "curve":
        assert target.curve is not None
        phase_log.info(
            "%s curve: print program along the target, verified by the forward simulation",
            target.curve.family,
            extra={"task": True},
        )
        speeds = (opt.min_speed, opt.max_speed)
        fm = target.filament_model()
        table = cached_response_table(
            speed_range=speeds,
            max_omega_star=min(opt.radius * opt.max_rotation / opt.min_speed, 2.5),
            radius=opt.radius,
            temperature=opt.temperature,
            model=fm,
            active_material=opt.active_material,
            passive_material=opt.passive_material,
        )
        fil = design_filament(
            curve_points(target.curve),
            spacing=opt.spacing,
            radius=opt.radius,
            temperature=opt.temperature,
            speed_range=speeds,
            max_rotation=opt.max_rotation,
            table=table,
            model=target.filament_model(),
            active_material=opt.active_material,
            passive_material=opt.passive_material,
        )
        simple = simplest_program(
            fil,
            table,
            tolerance=opt.tolerance,
            speed_range=speeds,
            max_rotation=opt.max_rotation,
            spacing=opt.spacing,
            temperature=opt.temperature,
            model=fm,
            name=name,
            inks={**_inks_entry(target), "filament": _ink_names(target)},
            materials=target.material_set,
        )
        runs = simple.settings
        notes = list(fil.notes)
        if not simple.within_tolerance:
            notes.append(
                f"no design of rounded, piecewise-constant settings met the tolerance "
                f"{100 * opt.tolerance:.2g} % of the length; the closest is returned"
            )
        summary: dict[str, Any] = {
            "kind": "curve",
            "family": target.curve.family,
            "length_mm": float(np.sum(np.linalg.norm(np.diff(fil.target, axis=0), axis=1))),
            "print_settings": simple.text(),
            "segments": [seg.record() for seg in simple.segments],
            "segment_count": len(runs),
            "rounding": {"speed_mm_s": SPEED_STEP, "rotation_number": ROTATION_STEP},
            "conventions": CONVENTION,
            "handedness": sorted({seg.handedness for seg in runs}),
            "rms_error_mm": simple.rms_error,
            "rms_error_rel": simple.rms_error_rel,
            "tolerance_rel": opt.tolerance,
            "within_tolerance": simple.within_tolerance,
            "rms_error_rel_per_vertex_design": fil.rms_error_rel,
            "fully_reachable": fil.fully_reachable,
            "unreachable_stretches_mm": fil.unreachable_stretches(),
            "flips": fil.flips,
            "speed_range_mm_s": [min(x.speed for x in runs), max(x.speed for x in runs)],
            "rotation_number_range": [
                min(x.rotation_number for x in runs),
                max(x.rotation_number for x in runs),
            ],
            "notes": notes,
            "verified_by": "forward simulation of the design file's print program (free "
            "filament; rod solver)",
            **_verified_state(simple.achieved, simple.stable, opt.radius),
        }
        return InverseRun(target, simple.design, summary, [], fil, simple)
    assert target.lattice is not None
    spec = target.lattice
    lat = sinusoidal_lattice(
        spec.n,
        spec.spacing,
        spec.amplitude,
        spec.ghost_nodes,
        pattern="dome" if target.kind != "saddle" else "saddle",
        active_material=opt.active_material,
        passive_material=opt.passive_material,
    )
    log: list[tuple[int, float]] = []

    def cb(it: int, value: float) -> None:
        log.append((it, value))
        if progress is not None:
            progress(it, value)

    phase_log.info(
        "%dx%d lattice, %s target: edge modes and speeds by adjoint optimisation (at most %d "
        "iterations), then rounded and verified",
        spec.n,
        spec.n,
        target.kind,
        opt.max_iterations,
        extra={"task": True},
    )
    surf = target.surface_target()
    # lattices are designed where they live: the declared [contact] table, else the bath
    contact = bath_contact() if target.contact is None else target.contact
    des = design_in_bath(
        lat,
        surf,
        contact=contact,
        temperature=opt.temperature,
        robust=opt.robust,
        filament_model=target.filament_model(),
        materials=target.material_set,
        max_iterations=opt.max_iterations,
        speed_range=(opt.min_speed, opt.max_speed),
        speed_resolution=opt.speed_resolution,
        callback=cb,
    )
    assert des.bath is not None
    k_t = des.target_gaussian_curvature
    k_a = des.achieved_gaussian_curvature
    summary = {
        "kind": target.kind,
        "lattice": {"n": spec.n, "spacing_mm": spec.spacing, "amplitude_mm": spec.amplitude},
        "assumptions": "lattice spacing, amplitude and ghost nodes are design choices "
        "(not given by the paper)",
        "target_gaussian_curvature": k_t,
        "achieved_gaussian_curvature": k_a,
        "gaussian_curvature_error_rel": None if k_t is None else abs(k_a - k_t) / abs(k_t),
        "misfit_rms_mm": des.misfit_rms,
        "misfit_rel": des.misfit_rel,
        "stable": des.stable,
        "reached": des.bath.reached,
        "optimised_gaussian_curvature": des.optimised_gaussian_curvature,
        "verified": des.bath.record(),
        "band": None if des.band is None else des.band.record(),
        "robust": None if des.robust is None else des.robust.record(),
        "iterations": des.iterations,
        "forward_solves": des.solves,
        "expanding_edges": int(np.sum(des.modes > 0)),
        "contracting_edges": int(np.sum(des.modes < 0)),
        "speed_range_mm_s": [float(des.speeds.min()), float(des.speeds.max())],
        "contact": surroundings_record(contact, opt.temperature, along_ramp=True),
        "designed_in": "optimised frictionless with self-contact, floor and weight as declared "
        "(on the lift probe's branch), verified by the ramp rotomorph simulate runs on the "
        "design file (its friction and path check included)",
    }
    design_file = lattice_design_file(des, name, contact, target)
    return InverseRun(target, design_file, summary, log, des)


def _verified_state(achieved: FloatArray, stable: bool | None, radius: float) -> dict[str, Any]:
    """Whether the verifying equilibrium of a filament design is physical: a certified stable
    minimum whose filament does not pass through itself (no contact is modelled)."""
    from rotomorph.simulate.run_data import chain_clearance

    clearance = float(chain_clearance(achieved[None], 2.0 * radius)[0])
    reasons = []
    if stable is False:
        reasons.append("the verifying equilibrium is not a stable minimum")
    if clearance < 1.0:
        reasons.append(
            f"the achieved shape passes through itself (clearance {clearance:.2f} diameters, "
            "contact not modelled)"
        )
    verdict = "no" if reasons else ("unknown" if stable is None else "yes")
    reason = "; ".join(reasons) or ("stability not checked" if verdict == "unknown" else "")
    return {
        "stable": stable,
        "min_clearance_diameters": min(clearance, 2.0),
        "physical": {"verdict": verdict, "reason": reason or "all checks passed"},
    }


def write_inverse(run: InverseRun, design_path: str | Path) -> list[Path]:
    """Write the design file and, in ``<design stem>_inverse/``, the summary, log and figures."""
    from rotomorph.inverse.figures import inverse_figures

    design_path = Path(design_path)
    design_path.parent.mkdir(parents=True, exist_ok=True)
    design = run.design
    if isinstance(design.materials, str):  # the materials file, relative to the design file
        data = design.model_dump(mode="python")
        data["materials"] = os.path.relpath(design.materials, design_path.parent.resolve())
        design = parse_design(data, base=design_path.parent, materials=design.material_set)
    out = [save_design(design, design_path)]
    folder = design_path.with_name(design_path.stem + "_inverse")
    folder.mkdir(parents=True, exist_ok=True)
    out.append(atomic_write_text(folder / "summary.json", json.dumps(run.summary, indent=2) + "\n"))
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["iteration", "objective"])
    w.writerows(run.log)
    out.append(atomic_write_text(folder / "convergence.csv", buf.getvalue()))
    if run.result is not None:
        out += inverse_figures(run.result, folder, program=run.program)
    return out


def inverse_file(
    target_path: str | Path,
    design_path: str | Path,
    progress: Callable[[int, float], None] | None = None,
) -> str:
    """Run the target file at ``target_path`` and write the results; returns a one-line summary."""
    from rotomorph.inverse.targets import load_target

    target = load_target(str(target_path))
    run = run_inverse(target, progress)
    write_inverse(run, design_path)
    s = run.summary
    folder = Path(design_path).with_name(Path(design_path).stem + "_inverse")
    if target.kind == "curve":
        reach = "all reachable" if s["fully_reachable"] else "NOT all reachable (see summary)"
        state = {"yes": "verified state physical", "unknown": "verified state unverified"}.get(
            s["physical"]["verdict"], f"verified state NOT PHYSICAL: {s['physical']['reason']}"
        )
        within = "" if s["within_tolerance"] else " (NOT within the tolerance)"
        return (
            f"wrote {design_path} and {folder}/: {s['print_settings']} (speed to "
            f"{SPEED_STEP:g} mm/s, ω* to {ROTATION_STEP:g}; ω* > 0: nozzle counter-clockwise "
            f"from above); RMS error {s['rms_error_mm']:.3g} mm ({100 * s['rms_error_rel']:.2g} "
            f"% of the length, tolerance {100 * s['tolerance_rel']:.2g} %){within}, {reach}, "
            f"{s['flips']} flips; {state}"
        )
    k_t, k_a = s["target_gaussian_curvature"], s["achieved_gaussian_curvature"]
    kt = "" if k_t is None else f"target K {k_t:.3g} 1/mm², "
    band = "" if s["band"] is None else f" ± {s['band']['gaussian_curvature_sd_calibration']:.2g}"
    sd_n = None if s["band"] is None else s["band"].get("gaussian_curvature_sd_nuisance")
    nuisance = "" if sd_n is None else f", ± {sd_n:.2g} (nuisance inputs)"
    where = _surroundings_text(s["contact"])
    verdict = "REACHED" if s["reached"] else f"NOT REACHED: {s['verified']['reason']}"
    return (
        f"wrote {design_path} and {folder}/: designed and verified {where} by simulate's "
        f"ramp: {kt}verified K {k_a:.3g}{band} 1/mm² (calibration band){nuisance}, misfit "
        f"{s['misfit_rms_mm']:.3g} mm ({100 * s['misfit_rel']:.2g} % of the size); {verdict}"
    )


def _surroundings_text(record: dict[str, Any] | None) -> str:
    """``in the bath (self-contact, floor, buoyant weight)`` from a surroundings record."""
    if record is None:
        return "free (no contact, no weight)"
    parts = [
        name
        for name, key in (
            ("self-contact", "self_contact"),
            ("floor", "floor"),
            ("buoyant weight", "gravity"),
        )
        if record.get(key)
    ]
    if record.get("friction"):
        parts.append(f"friction {record['friction']:g}")
    where = "in the bath" if record.get("gravity") else "in contact"
    return f"{where} ({', '.join(parts) or 'no contact, no weight'})"
