"""Simulate a whole design file: its filaments (rod solver per filament) or its lattice.

:func:`simulate_design` returns a :class:`DesignSimulation` holding everything one results file
stores (:func:`rotomorph.io.results.write_results`): positions per step, topology, per-step
scalars and fields with units, and metadata. Several filaments share one network of disjoint
chains (node offsets in ``metadata["chains"]``); they are solved independently.

Lattices go through :func:`rotomorph.lattice.heating.heat_lattice` (imported when needed).
"""

from __future__ import annotations

import logging
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path as FilePath
from typing import Any

import numpy as np

import rotomorph
from rotomorph._display import compact_display
from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.analysis.curvature import network_relative_curvature_change
from rotomorph.errors import InvalidDesignError, InvalidParameterError
from rotomorph.io.designfile import design_size, with_spacing
from rotomorph.io.results import RunResults, to_jsonable
from rotomorph.materials.natural import FilamentModel, named_model
from rotomorph.simulate.filament import (
    ACTUATION_TEMPERATURE,
    PRINT_TEMPERATURE,
    FilamentSimulation,
    simulate_filament,
)
from rotomorph.simulate.inks import design_model, materials_record
from rotomorph.simulate.options import TEMPERATURE_ACTUATIONS, check_run_options
from rotomorph.simulate.surroundings import (
    filament_surroundings,
    lattice_surroundings,
    surroundings_record,
)

__all__ = [
    "DesignSimulation",
    "StepReport",
    "filaments_simulation",
    "simulate_design",
    "step_count",
]

Progress = Callable[[int], None]
#: Phase messages (set-up, solve, analysis); the CLI shows them on a terminal.
phase_log = logging.getLogger("rotomorph.progress")


@compact_display()
@dataclass(frozen=True, eq=False)
class DesignSimulation:
    """Shapes of a design over heating, in the layout of a results file.

    Attributes
    ----------
    kind
        ``"filaments"`` or ``"lattice"``.
    design
        The resolved design (JSON-compatible).
    edges, branch
        Topology ``(E, 2)`` and branch flags ``(N,)``.
    positions
        ``(S, N, 3)`` node positions per step (mm).
    scalars, fields, units
        Per-step scalars ``(S,)`` and arrays ``(S, ...)`` by name, and their units.
    metadata
        Run information (version, timings, per-filament or lattice results).
    filaments
        Per-filament results (``kind == "filaments"``).
    lattice
        The lattice heating result (``kind == "lattice"``).
    """

    kind: str
    design: Mapping[str, Any]
    edges: IntArray
    branch: BoolArray
    positions: FloatArray
    scalars: Mapping[str, FloatArray]
    fields: Mapping[str, FloatArray] = field(default_factory=dict)
    units: Mapping[str, str] = field(default_factory=dict)
    metadata: Mapping[str, Any] = field(default_factory=dict)
    filaments: tuple[FilamentSimulation, ...] = ()
    lattice: Any = None

    def save(self, folder: str | os.PathLike[str], *, movie: bool = True) -> list[FilePath]:
        """Write the run folder of ``rotomorph simulate`` into ``folder``; return the paths."""
        from rotomorph.simulate.outputs import write_run

        return write_run(self, folder, movie=movie)

    def plot(self, folder: str | os.PathLike[str], *, movie: bool = False) -> list[FilePath]:
        """Draw the run's figures (and, with ``movie``, the animation) into ``folder``."""
        from rotomorph.simulate.outputs import plot_run
        from rotomorph.simulate.run_data import describe_run

        return plot_run(describe_run(self), folder, movie=movie)

    def run_results(self) -> RunResults:
        """The same data as :class:`~rotomorph.io.results.RunResults` (what the file holds)."""
        return RunResults(
            design=self.design,
            edges=self.edges,
            branch=self.branch,
            positions=self.positions,
            scalars=dict(self.scalars),
            fields=dict(self.fields),
            units={"positions": "mm", **self.units},
            metadata=to_jsonable(dict(self.metadata)),
        )


@dataclass(frozen=True, eq=False)
class StepReport:
    """One converged step of a running :func:`simulate_design` (``on_step``), before the run ends.

    Attributes
    ----------
    unit, units
        Which filament (0-based) of how many is being heated (a lattice: 0 of 1).
    step, steps
        Step index ``k`` of ``steps + 1`` states (0: the printed state).
    value, ramp
        The ramp's value at this step and its name: ``"temperature"`` (°C) or ``"actuation"``.
    positions
        Node positions ``(N_unit, 3)`` (mm, lab frame: a lattice's origin added) of this
        filament or of the lattice.
    state
        The rod state (material directors give the Janus sides).
    stable
        True where the solver certified a stable minimum, None where it did not check.
    residual, max_axial_strain
        The step's relative residual and largest centre-line strain (0 at the printed step).
    """

    unit: int
    units: int
    step: int
    steps: int
    value: float
    ramp: str
    positions: FloatArray
    state: Any
    stable: bool | None
    residual: float
    max_axial_strain: float


StepCallback = Callable[[StepReport], None]


def _reporter(
    on_step: StepCallback | None,
    unit: int,
    units: int,
    steps: int,
    ramp: str,
    origin: Any = (0.0, 0.0, 0.0),
) -> Any:
    """The lower layers' ``on_step(k, value, state, result)`` as :class:`StepReport` calls."""
    if on_step is None:
        return None
    shift = np.asarray(origin, dtype=float)
    callback = on_step

    def report(k: int, value: float, state: Any, result: Any) -> None:
        callback(
            StepReport(
                unit=unit,
                units=units,
                step=int(k),
                steps=int(steps),
                value=float(value),
                ramp=ramp,
                positions=np.asarray(state.positions, dtype=float) + shift,
                state=state,
                stable=True if result is None or getattr(result, "stable", None) is True else None,
                residual=0.0 if result is None else float(result.residual),
                max_axial_strain=0.0
                if result is None
                else float(getattr(result, "max_axial_strain", np.nan)),
            )
        )

    return report


def step_count(design: Any, steps: int) -> int:
    """Progress units :func:`simulate_design` reports for ``design`` (for a progress bar):
    every filament's states (``steps + 1`` each), or a lattice's ramp steps, those of its
    path check's sub-stepped ramp included (:func:`~rotomorph.lattice.heating.heat_lattice`)."""
    if design.lattice is not None:
        factor = int(getattr(design.contact, "path_check", 1) or 1)
        return steps * (1 + factor) if factor > 1 else steps
    return len(design.filaments) * (steps + 1)


def _about_seconds(seconds: float) -> str:
    """An estimate in words: ``"under 1 s"``, ``"about 4 s"``, ``"about 3 min"``."""
    if seconds < 1.0:
        return "under 1 s"
    if seconds < 90.0:
        return f"about {seconds:.0f} s"
    return f"about {seconds / 60:.0f} min"


def _about_bytes(count: float) -> str:
    """An estimate in words: ``"about 40 MB"``, ``"about 1.2 GB"``."""
    if count < 1e9:
        return f"about {max(count / 1e6, 1):.0f} MB"
    return f"about {count / 1e9:.1f} GB"


#: A helix fit describes a shape when its rms residual is below this fraction of its radius.
HELIX_FIT_RTOL = 0.1


#: A fitted helix of fewer turns than this (a filament bent through less than one radian about
#: the helix axis) is a gently bent filament, not a helix or coil.
HELIX_MIN_TURNS = 1.0 / (2.0 * np.pi)


def _helix_rejection(sim: FilamentSimulation) -> str | None:
    """Why the fitted helix does not describe the shape (``None``: it does)."""
    h = sim.helix
    if h is None:
        return "no helix fitted"
    if not h.rms_residual <= HELIX_FIT_RTOL * h.radius:
        return f"rms residual above {HELIX_FIT_RTOL:g} x the fitted radius"
    if not h.turns >= HELIX_MIN_TURNS:
        return (
            f"the fitted helix makes {h.turns:.2g} turn (bent through less than one radian): a "
            "gently bent filament, not a helix or coil"
        )
    return None


def shape_label(sim: FilamentSimulation) -> str | None:
    """The morphology label of a simulated filament's final shape where it describes the shape:
    ``"straight"`` and ``"twisted rod"`` (labels of a straight centre line, which claim no
    helix), or ``"helix"``/``"coil"`` where the fitted helix fits (rms residual below
    :data:`HELIX_FIT_RTOL` of its radius, at least :data:`HELIX_MIN_TURNS` turns); ``None``
    otherwise (a gently bent arc is not a coil, a sinusoid not a helix). ``summary.json`` and
    sweep tables both give this."""
    if sim.morphology.value in ("straight", "twisted rod") or _helix_rejection(sim) is None:
        return str(sim.morphology.value)
    return None


def _filament_summary(sim: FilamentSimulation) -> dict[str, Any]:
    # a shape label and a helix fit only where the fitted helix describes the shape (not on
    # sinusoids or graded filaments, whose fits leave millimetre residuals, nor on a
    # straightened sinusoid that a helix of 70 mm radius and 0.06 turn fits to 0.1 mm)
    rejection = _helix_rejection(sim)
    fits = rejection is None
    out: dict[str, Any] = {
        "name": sim.name,
        "end_to_end_ratio": sim.final_ratio,
        "morphology": shape_label(sim),
        "iterations": int(sim.iterations.sum()),
        "wall_time_s": round(sim.wall_time, 3),
    }
    if sim.helix is not None and not fits:
        out["helix_fit_rejected"] = {
            "rms_residual_mm": sim.helix.rms_residual,
            "radius_mm": sim.helix.radius,
            "turns": sim.helix.turns,
            "reason": rejection,
        }
    if sim.helix is not None and fits:
        out["helix"] = {
            "radius_mm": sim.helix.radius,
            "pitch_mm": sim.helix.pitch,
            "handedness": sim.helix.handedness,
            "turns": sim.helix.turns,
            "rms_residual_mm": sim.helix.rms_residual,
        }
    if sim.closed_form is not None:
        out["closed_form_end_to_end_ratio"] = float(sim.closed_form.end_to_end_ratio)
        out["closed_form_shape"] = str(sim.closed_form.label)
    return out


def _simulate_filaments(
    design: Any,
    *,
    steps: int,
    start_temperature: float,
    temperature: float,
    model: FilamentModel | str | None,
    progress: Progress | None,
    on_step: StepCallback | None = None,
) -> DesignSimulation:
    sims = []
    for i, fil in enumerate(design.filaments):
        phase_log.info(
            "filament %d of %d %r (%s rod nodes, %d heating steps)",
            i + 1,
            len(design.filaments),
            fil.name or f"filament {i}",
            f"{fil.node_count():,}",
            steps,
            extra={"task": True},
        )
        program = fil.to_program()
        fil_model = design_model(design, fil.active_material, fil.passive_material, model)
        contact, loads = filament_surroundings(design.contact, program, fil, design.material_set)
        sims.append(
            simulate_filament(
                program,
                name=fil.name or f"filament {i}",
                steps=steps,
                start_temperature=start_temperature,
                temperature=temperature,
                model=fil_model,
                progress=progress,
                contact=contact,
                loads=loads,
                on_step=_reporter(on_step, i, len(design.filaments), steps, "temperature"),
            )
        )
    sim = filaments_simulation(
        sims, design.model_dump(mode="json"), temperatures=(start_temperature, temperature)
    )
    record = surroundings_record(design.contact, temperature, along_ramp=True, lattice=False)
    if record is None:
        return sim
    return replace(sim, metadata={**sim.metadata, "contact": record})


def filaments_simulation(
    sims: Sequence[FilamentSimulation],
    design: Mapping[str, Any],
    *,
    temperatures: tuple[float, float] | None = None,
) -> DesignSimulation:
    """Filament simulations as one :class:`DesignSimulation` (disjoint chains of one network).

    Parameters
    ----------
    sims
        One or more :class:`~rotomorph.simulate.filament.FilamentSimulation` of the same ramp.
    design
        The design they come from (JSON-compatible), stored with the results.
    temperatures
        First and last temperature (°C); default: the simulations' own.
    """
    sims = list(sims)
    if not sims:
        raise InvalidParameterError("sims", "needs at least one filament simulation")
    first = sims[0]
    if temperatures is None:
        temperatures = (float(first.temperature[0]), float(first.temperature[-1]))
    steps = len(first.temperature) - 1
    if any(len(s.temperature) != steps + 1 for s in sims):
        raise InvalidParameterError("sims", "must all have the same number of heating steps")
    sizes = [len(s.printed) for s in sims]
    offsets = np.concatenate([[0], np.cumsum(sizes)])
    edges = np.concatenate(
        [
            np.stack([np.arange(n - 1), np.arange(1, n)], axis=1) + o
            for n, o in zip(sizes, offsets, strict=False)
        ]
    )
    scalars = {
        "temperature": first.temperature,
        "actuation": first.actuation,
        "energy": np.sum([s.energy for s in sims], axis=0),
        "iterations": np.sum([s.iterations for s in sims], axis=0),
        "residual": np.max([s.residual for s in sims], axis=0),
    }
    if len(sims) == 1:  # several filaments: per filament only (a mean ratio describes none)
        scalars["end_to_end_ratio"] = sims[0].end_to_end_ratio
    fields = {
        "end_to_end_ratio_per_filament": np.stack([s.end_to_end_ratio for s in sims], axis=1),
        "curvature": np.concatenate([s.curvature for s in sims], axis=1),
    }
    metadata = {
        "kind": "filaments",
        "chains": [
            {"name": s.name, "start": int(o), "stop": int(o + n)}
            for s, o, n in zip(sims, offsets, sizes, strict=False)
        ],
        "filaments": [_filament_summary(s) for s in sims],
        "temperature_range_degC": list(temperatures),
        "steps": steps,
        "rotomorph_version": rotomorph.__version__,
        "design_name": str(design.get("name", "")),
    }
    return DesignSimulation(
        kind="filaments",
        design=dict(design),
        edges=edges.astype(np.int64),
        branch=np.zeros(int(offsets[-1]), dtype=bool),
        positions=np.concatenate([s.positions for s in sims], axis=1),
        scalars=scalars,
        fields=fields,
        units={
            "end_to_end_ratio_per_filament": "1",
            "curvature": "1/mm",
        },
        metadata=metadata,
        filaments=tuple(sims),
    )


#: Lattice actuation used when none is given (as rotomorph.lattice.actuation.DEFAULT_ACTUATION,
#: repeated here so that filament-only runs do not import the lattice package).
DEFAULT_ACTUATION = "program"


def lattice_assumptions(lattice: Any) -> dict[str, Any]:
    """The lattice's geometric inputs that the paper does not give, with their values.

    Every lattice output depends on them (area, curvature, clearance); they are assumptions,
    not measurements, and results carry them so that no number hides them.
    """
    from rotomorph.design.lattices import ASSUMED_FIELDS

    values = {name: float(getattr(lattice, name)) for name in ASSUMED_FIELDS}
    return {
        **{f"{k}_mm": v for k, v in values.items()},
        "wavelength_mm": float(lattice.spacing),
        "note": "not given in the paper: cell size l (= the sine wavelength), amplitude A "
        "and filament radius R are assumed; every lattice number depends on them",
    }


def _lattice_actuation(
    rule: str,
    start_temperature: float | None,
    temperature: float | None,
    model: FilamentModel | None,
) -> Any:
    """The actuation of a lattice run: the registered rule, ramped over the run's temperatures
    (default 25 → 175 °C) with its materials model when it is temperature-driven."""
    from rotomorph.lattice.actuation import get_actuation

    if rule not in TEMPERATURE_ACTUATIONS:
        return rule
    start = PRINT_TEMPERATURE if start_temperature is None else float(start_temperature)
    end = ACTUATION_TEMPERATURE if temperature is None else float(temperature)
    if not start < end:
        raise InvalidParameterError(
            "temperature", f"must exceed the start temperature {start:g} °C; got {end:g} °C"
        )
    base: Any = get_actuation(rule)  # ProgramActuation or ThermalActuation (dataclasses)
    return replace(base, start=start, end=end, filament_model=model)


def _simulate_lattice(
    design: Any,
    *,
    steps: int,
    actuation: str,
    progress: Progress | None,
    start_temperature: float | None = None,
    temperature: float | None = None,
    model: FilamentModel | str | None = None,
    on_step: StepCallback | None = None,
) -> DesignSimulation:
    from rotomorph.lattice.heating import heat_lattice  # lattice-only

    lat = design.lattice
    size = design_size(design)
    phase_log.info(
        "set-up: %dx%d lattice geometry, %s rod nodes (estimated %s of memory, %s of "
        "set-up); %d heating step(s)",
        lat.n,
        lat.n,
        f"{size.nodes:,}",
        _about_bytes(size.memory_bytes),
        _about_seconds(size.setup_seconds),
        steps,
        extra={"task": True},
    )
    lattice = lat.to_lattice()
    model = design_model(design, lat.active_material, lat.passive_material, model)
    rule = _lattice_actuation(actuation, start_temperature, temperature, model)
    hot = float(getattr(rule, "end", ACTUATION_TEMPERATURE))  # x-readings: the paper's 175 °C
    in_temperature = actuation in ("thermal", "program")  # else the ramp is an abstract x
    ramp = "temperature" if in_temperature else "actuation"
    res = heat_lattice(
        lattice,
        actuation=rule,
        steps=steps,
        on_step=_reporter(on_step, 0, 1, steps, ramp, design.lattice.origin),
        **lattice_surroundings(
            design.contact,
            lattice,
            hot,
            ramp_in_temperature=in_temperature,
            materials=design.material_set,
        ),
        progress=progress,
    )
    phase_log.info("analysis: curvature changes, areas")
    pos = np.asarray(res.positions, dtype=float) + np.asarray(design.lattice.origin, dtype=float)
    rel = np.stack([network_relative_curvature_change(p, pos[0], lattice.edge_chains) for p in pos])
    scalars = {
        ramp: np.asarray(res.parameter, dtype=float),
        "energy": np.asarray(res.energy, dtype=float),
        "iterations": np.asarray(res.iterations, dtype=float),
        "residual": np.asarray(res.residual, dtype=float),
        "area_ratio": np.asarray(res.area_ratio, dtype=float),
        "gaussian_sign": np.asarray(res.gaussian_sign, dtype=float),
        "characteristic_curvature": np.asarray(res.characteristic_curvature, dtype=float),
        "edge_strain": np.asarray(res.mean_edge_strain, dtype=float),
        "min_clearance": np.asarray(res.min_clearance, dtype=float),
    }
    if res.stack_overlaps is not None:  # layer pairs of the printed stack interpenetrating
        scalars["stack_overlaps"] = np.asarray(res.stack_overlaps, dtype=float)
    fields = {
        "relative_curvature_change": rel,
        "edge_end_to_end_ratio": np.asarray(res.edge_ratios, dtype=float),
    }
    metadata = {
        "kind": "lattice",
        "pattern": design.lattice.pattern,
        "n": design.lattice.n,
        "steps": steps,
        "edge_mode": list(lattice.edge_mode),
        "actuation_rule": res.actuation,
        "contact": surroundings_record(design.contact, hot, along_ramp=in_temperature),
        "assumptions": lattice_assumptions(lattice),
        "lattice_wall_time_s": float(np.sum(res.wall_time)),
        "path_check": None if res.path_check is None else res.path_check.note,
    }
    net = lattice.network
    return DesignSimulation(
        kind="lattice",
        design=design.model_dump(mode="json"),
        edges=np.asarray(net.edges, dtype=np.int64),
        branch=np.asarray(net.branch, dtype=bool),
        positions=pos,
        scalars=scalars,
        fields=fields,
        units={
            "relative_curvature_change": "1",
            "edge_end_to_end_ratio": "1",
            "min_clearance": "1",
            "stack_overlaps": "1",
        },
        metadata=metadata,
        lattice=res,
    )


def simulate_design(
    design: Any,
    *,
    steps: int = 8,
    start_temperature: float | None = None,
    temperature: float | None = None,
    model: FilamentModel | str | None = None,
    spacing: float | None = None,
    actuation: str | None = None,
    progress: Progress | None = None,
    on_step: StepCallback | None = None,
) -> DesignSimulation:
    """Predicted shapes of a design (:class:`rotomorph.io.designfile.Design`) over heating.

    Parameters
    ----------
    design
        A validated design with filaments or a lattice (not both).
    steps
        Heating steps; results hold ``steps + 1`` states.
    start_temperature, temperature
        Temperature ramp (°C; default 25 → 175 °C, range
        :data:`rotomorph.simulate.options.TEMPERATURE_RANGE`) of filaments and of lattices
        heated by a temperature-driven actuation (``program``, ``thermal``); refused with the
        paper's x-readings, which ramp x from 0 to 0.75.
    model
        Filament modelling choices (default calibrated :class:`FilamentModel`), or its name
        (:func:`~rotomorph.materials.natural.named_model`: ``"calibrated"``,
        ``"warner-terentjev"``, ``"room-temperature"``); filaments and temperature-driven
        lattices.
    spacing
        Override the filaments' vertex spacing (mm; the design is re-validated); coarser is
        faster. Filaments only.
    actuation
        Lattice actuation rule (:data:`rotomorph.lattice.actuation.ACTUATIONS`; default
        ``"program"``: each line's natural field from its print program). Refused for
        filaments.
    progress
        Called with the number of finished units (see :func:`step_count`).
    on_step
        Called with a :class:`StepReport` as each step of each filament (or of the lattice) is
        reached, the printed state first: to show converged states while the run goes on
        (the app streams them). A lattice with ``contact.path_check > 1`` reports its first
        ramp; the run's result may keep the sub-stepped ramp's end state instead.

    Raises
    ------
    InvalidDesignError
        A design with both filaments and a lattice.
    InvalidParameterError
        An option that does not apply to the design, or out of range
        (:func:`rotomorph.simulate.options.check_run_options`).
    ConvergenceError
        A solve failed.
    """
    t0 = time.perf_counter()
    if design.filaments and design.lattice is not None:
        raise InvalidDesignError(
            "lattice", "simulate handles filaments or a lattice, not both; split the design file"
        )
    check_run_options(  # a model name is resolved per ink pair (design_model)
        "lattice" if design.lattice is not None else "filaments",
        steps=steps,
        start_temperature=start_temperature,
        temperature=temperature,
        spacing=spacing,
        model=named_model(model) if isinstance(model, str) else model,
        actuation=actuation,
    )
    if design.lattice is not None:
        sim = _simulate_lattice(
            design,
            steps=steps,
            actuation=actuation or DEFAULT_ACTUATION,
            progress=progress,
            start_temperature=start_temperature,
            temperature=temperature,
            model=model,
            on_step=on_step,
        )
    else:
        if spacing is not None:
            design = with_spacing(design, spacing)
        sim = _simulate_filaments(
            design,
            steps=steps,
            start_temperature=PRINT_TEMPERATURE if start_temperature is None else start_temperature,
            temperature=ACTUATION_TEMPERATURE if temperature is None else temperature,
            model=model,
            progress=progress,
            on_step=on_step,
        )
    meta = dict(sim.metadata)
    meta.update(
        rotomorph_version=rotomorph.__version__,
        design_name=design.name,
        design_sha256=design.sha256(),
        materials=materials_record(design),
        wall_time_s=round(time.perf_counter() - t0, 3),
    )
    return replace(sim, metadata=meta)
