"""One run of a sweep: its resolved design, its deterministic id, and the function computing it.

A run id is the sha256 (hex) of the canonical JSON (sorted keys, no spaces) of::

    {"design": <resolved design, every default filled in>, "settings": <sweep settings>,
     "machine": <machine profile or null>, "version": <rotomorph version>}

so two points that resolve to the same design share one run, and a new rotomorph version (or a
change of settings) computes afresh. :func:`execute_run` is a plain module-level function of a
small picklable :class:`RunSpec`: it never raises for a bad run, it returns the error instead,
so any ``concurrent.futures.Executor`` (a process pool, a Dask client's executor, a
dask-jobqueue cluster) can run it.

Statuses: ``ok``; ``invalid`` (the point is not a valid design, or the machine profile cannot
print it: :class:`~rotomorph.errors.InvalidParameterError`,
:class:`~rotomorph.errors.MachineLimitError`); ``failed`` (the computation raised, e.g.
:class:`~rotomorph.errors.ConvergenceError`, or an unexpected exception, whose traceback is
kept in the diagnostics).
"""

from __future__ import annotations

import contextlib
import hashlib
import json
import logging
import os
import socket
import threading
import time
import traceback
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from typing import Any

import rotomorph
from rotomorph.errors import (
    ConvergenceError,
    InvalidParameterError,
    MachineLimitError,
    RotomorphError,
)
from rotomorph.io.designfile import parse_design
from rotomorph.io.results import RunResults, to_jsonable
from rotomorph.sweep.metrics import (
    closed_form_metrics,
    filament_metrics,
    filament_model,
    lattice_metrics,
)
from rotomorph.sweep.paths import set_path
from rotomorph.sweep.spec import Sweep

__all__ = ["STATUSES", "RunOutcome", "RunSpec", "error_record", "execute_run", "resolve_run"]

#: Values of a run's ``status``.
STATUSES = ("ok", "invalid", "failed")


@dataclass(frozen=True)
class RunSpec:
    """Everything one run needs (picklable, a few kB).

    Attributes
    ----------
    run_id
        sha256 hex of the resolved design, settings, machine and version (module docstring).
    design
        The resolved design (JSON-compatible); the unresolved mapping if it is invalid.
    settings
        The sweep's settings (JSON-compatible).
    machine
        Machine profile keys, or ``None``.
    hdf5
        Return the full results (for a per-run HDF5 file).
    error
        Set when the point is already known to be invalid (no computation needed).
    """

    run_id: str
    design: Mapping[str, Any]
    settings: Mapping[str, Any]
    machine: Mapping[str, Any] | None = None
    hdf5: bool = False
    error: Mapping[str, Any] | None = None

    def __dask_tokenize__(self) -> tuple[str, str, bool]:
        """Dask's task key for this spec: the run id already hashes the design, settings,
        machine and version, so Dask need not walk the whole design again (about 10 ms of the
        submitting process's CPU per task otherwise)."""
        return ("rotomorph.sweep.RunSpec", self.run_id, self.hdf5)


@dataclass(frozen=True, eq=False)
class RunOutcome:
    """What :func:`execute_run` returns: the run's record and, if asked, its full results."""

    record: Mapping[str, Any]
    results: RunResults | None = None


def _run_id(design: Any, settings: Any, machine: Any) -> str:
    blob = {
        "design": design,
        "settings": settings,
        "machine": machine,
        "version": rotomorph.__version__,
    }
    text = json.dumps(to_jsonable(blob), sort_keys=True, separators=(",", ":"))
    return hashlib.sha256(text.encode()).hexdigest()


def error_record(err: BaseException) -> dict[str, Any]:
    """``{"type", "message", "diagnostics"}`` of an exception (diagnostics JSON-compatible)."""
    diag: dict[str, Any] = {}
    if isinstance(err, InvalidParameterError):
        diag["field"] = err.field
    if isinstance(err, ConvergenceError) and err.result is not None:
        for key in ("status", "iterations", "factorizations", "energy", "residual", "decrement"):
            value = getattr(err.result, key, None)
            if value is not None:
                diag[key] = getattr(value, "value", value)
    if not isinstance(err, RotomorphError):
        diag["traceback"] = "".join(traceback.format_exception(err)[-6:])
    return {"type": type(err).__name__, "message": str(err), "diagnostics": to_jsonable(diag)}


def resolve_run(sweep: Sweep, point: Mapping[str, Any]) -> RunSpec:
    """The :class:`RunSpec` of one point of ``sweep`` (``{path: value}``).

    An invalid point (a path the design lacks, a value the design file rejects) gives a spec
    whose ``error`` is set; its id hashes the unresolved design instead.
    """
    settings = sweep.settings.model_dump(mode="json")
    data: Any = dict(sweep.design)
    try:
        for path, value in point.items():
            data = set_path(data, path, value)
        design = parse_design(data).model_dump(mode="json")
    except InvalidParameterError as err:
        raw = to_jsonable(data)
        return RunSpec(
            run_id=_run_id(raw, settings, sweep.machine),
            design=raw,
            settings=settings,
            machine=sweep.machine,
            hdf5=sweep.hdf5,
            error=error_record(err),
        )
    return RunSpec(
        run_id=_run_id(design, settings, sweep.machine),
        design=design,
        settings=settings,
        machine=sweep.machine,
        hdf5=sweep.hdf5,
    )


def _check_machine(design: Any, machine: Mapping[str, Any]) -> None:
    from rotomorph.io.gcode import gcode_text
    from rotomorph.io.machine import MachineProfile

    programs = design.to_programs()
    gcode_text(programs, MachineProfile.from_dict(machine), **design.gcode_options())


def _compute(spec: RunSpec) -> tuple[dict[str, Any], RunResults | None]:
    design = parse_design(dict(spec.design))
    if spec.machine is not None:
        _check_machine(design, spec.machine)
    s = spec.settings
    model = _sweep_model(design, s["filament_model"])
    if s["method"] == "closed_form":
        from rotomorph.materials.natural import natural_field
        from rotomorph.simulate.inks import design_model

        shapes = []
        for fil in design.filaments:
            if s["spacing"] is not None:
                fil = fil.model_copy(update={"spacing": s["spacing"]})
            pair = design_model(design, fil.active_material, fil.passive_material, model)
            field = natural_field(fil.to_program(), None, s["temperature"], model=pair)
            shapes.append(closed_form_metrics(field.morphology()))
        physical = {"verdict": "unknown", "reason": "closed form: no equilibrium was solved"}
        return {"filaments": shapes, "physical": physical}, None
    from rotomorph.simulate.design import simulate_design
    from rotomorph.simulate.options import TEMPERATURE_ACTUATIONS

    # simulate_design refuses options that do not apply: a lattice takes the actuation rule
    # (and, when that rule is driven by temperature, the ramp and the filament model),
    # filaments the temperatures, spacing and filament model
    lattice = design.lattice is not None
    ramped = not lattice or s["actuation"] in TEMPERATURE_ACTUATIONS
    sim = simulate_design(
        design,
        steps=s["steps"],
        start_temperature=s["start_temperature"] if ramped else None,
        temperature=s["temperature"] if ramped else None,
        model=model if ramped else None,
        spacing=None if lattice else s["spacing"],
        actuation=s["actuation"] if lattice else None,
    )
    from rotomorph.simulate.run_data import describe_run

    described = describe_run(sim)
    meta = described.metadata
    if sim.kind == "lattice":
        metrics: dict[str, Any] = {"lattice": lattice_metrics(sim)}
    else:
        summaries = list(meta.get("filaments") or [])
        summaries += [{}] * (len(sim.filaments) - len(summaries))
        metrics = {
            "filaments": [
                filament_metrics(f, summary)
                for f, summary in zip(sim.filaments, summaries, strict=True)
            ]
        }
    verdict = meta.get("physical") or {}
    metrics["physical"] = {"verdict": verdict.get("verdict"), "reason": verdict.get("reason")}
    return metrics, described if spec.hdf5 else None


def _sweep_model(design: Any, name: str) -> Any:
    """The model a sweep's ``filament_model`` names for ``design``: a name of
    :data:`~rotomorph.materials.natural.MODEL_NAMES` is resolved per ink pair of the design's
    materials file (``simulate`` does so); the paper's leave-one-group-out models apply to the
    paper's inks only."""
    from rotomorph.materials.natural import MODEL_NAMES

    if name in MODEL_NAMES:
        return name if design.material_set is not None else filament_model(name)
    if design.material_set is not None:
        raise InvalidParameterError(
            "settings.filament_model",
            f"{name!r} is the paper's calibration without one of its groups, for the paper's "
            "inks; a design with its own materials file takes one of "
            f"{', '.join(MODEL_NAMES)}",
        )
    return filament_model(name)


class _Collect(logging.Handler):
    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.thread = threading.get_ident()
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        if record.thread == self.thread:
            msg = record.getMessage()
            if msg not in self.messages and len(self.messages) < 20:
                self.messages.append(msg)


_QUIET_LOCK = threading.Lock()
_QUIET = {"runs": 0, "propagate": True}


@contextlib.contextmanager
def _captured_warnings() -> Iterator[list[str]]:
    """Collect the library's warnings of this run (kept in its record, not printed).

    Runs may overlap in one process (a thread pool, Dask's threads): the library logger stops
    propagating while any run is active and gets its own setting back when the last one ends
    (saving and restoring it per run would leave it off when two runs interleave)."""
    logger = logging.getLogger("rotomorph")
    handler = _Collect()
    with _QUIET_LOCK:
        if _QUIET["runs"] == 0:
            _QUIET["propagate"] = logger.propagate
            logger.propagate = False
        _QUIET["runs"] += 1
    logger.addHandler(handler)
    try:
        yield handler.messages
    finally:
        logger.removeHandler(handler)
        with _QUIET_LOCK:
            _QUIET["runs"] -= 1
            if _QUIET["runs"] == 0:
                logger.propagate = bool(_QUIET["propagate"])


def execute_run(spec: RunSpec) -> RunOutcome:
    """Compute one run; errors are returned in the record, never raised.

    The record holds ``run_id``, ``status`` (:data:`STATUSES`), ``metrics`` (all metrics of the
    run's kind, :mod:`rotomorph.sweep.metrics`), ``error`` (``None`` or type, message,
    diagnostics), ``warnings`` (the library's logged warnings during the run, at most 20
    distinct; not printed), ``wall_time_s``, ``version``, ``host`` and ``pid``.
    """
    t0 = time.perf_counter()
    metrics: dict[str, Any] = {}
    results = None
    error = spec.error
    warnings: list[str] = []
    if error is not None:
        status = "invalid"
    else:
        with _captured_warnings() as warnings:
            try:
                metrics, results = _compute(spec)
                status = "ok"
            except (InvalidParameterError, MachineLimitError) as err:
                status, error = "invalid", error_record(err)
            except Exception as err:  # a failed run must not stop the sweep
                status, error = "failed", error_record(err)
    record = {
        "run_id": spec.run_id,
        "status": status,
        "metrics": to_jsonable(metrics),
        "error": None if error is None else dict(error),
        "warnings": list(warnings),
        "wall_time_s": time.perf_counter() - t0,
        "version": rotomorph.__version__,
        "host": socket.gethostname(),
        "pid": os.getpid(),
    }
    return RunOutcome(record=record, results=results)
