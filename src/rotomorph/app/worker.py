"""The code a session's worker process runs: simulations and inverse designs, as events.

A worker is a separate process (started with ``spawn``, so it shares nothing with the web
server's threads) that receives one job at a time on its inbox and puts *events* (plain dicts
of numbers, strings and numpy arrays) on its outbox:

``ready``
    The worker is ready for jobs; ``warmed`` names the warm-up designs it heated (all of
    :data:`WARM_STAGES` when it was idle, fewer when a job arrived during the warm-up, none
    when it was started without one).
``topology``
    A simulation's network: ``edges``, per-edge ``radius`` and ``active_fraction``, the
    ``chains`` (one per filament), ``printed`` positions and the design's name.
``step``
    One converged step (:class:`rotomorph.simulate.design.StepReport`): ``unit``/``units``,
    ``step``/``steps``, ``value`` and ``ramp``, the unit's ``positions`` and the interface
    normals toward the active half ``normals`` (float32), ``stable``, ``residual`` and
    ``max_axial_strain``.
``phase``
    A phase message of the library's ``rotomorph.progress`` log (text, shown escaped).
``iteration``
    An inverse-design iteration and its objective.
``done``
    The job ended: a simulation's run folder (written by the CLI's own
    :func:`~rotomorph.simulate.outputs.write_run_results`), or an inverse design's: the design
    file :func:`~rotomorph.inverse.run.inverse_file` wrote (``rotomorph inverse``), read back as
    data, and its one-line summary.
``error``
    The job failed: the one-line message the CLI would print (``field: what and the fix``) and
    whether it was bad input or a failed computation.

The worker writes only into the folder the server gave it (a temporary folder of the session).
"""

from __future__ import annotations

import itertools
import logging
import queue
import traceback
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["run_worker"]

#: A tiny filament heated in one step: loads the compiled kernels from their cache.
WARM_DESIGN = {
    "schema_version": 1,
    "filaments": [
        {
            "speed": 1.0,
            "rotation_number": 0.25,
            "spacing": 1.0,
            "segments": [{"kind": "line", "length": 6.0}],
        }
    ],
}

#: A 3 × 3 lattice resting on the bath floor under its weight, heated in one step: compiles
#: or loads the lattice, contact and floor kernels a lattice's first step needs (without it,
#: the first converged step of a 5 × 5 lattice comes about 1.5 s later).
WARM_LATTICE = {
    "schema_version": 1,
    "lattice": {
        "n": 3,
        "spacing": 5.0,
        "amplitude": 1.25,
        "ghost_nodes": 4,
        "pattern": "dome",
        "speed": 3.0,
    },
    "contact": {"self_contact": True, "floor": True, "gravity": True},
}


class _Phases(logging.Handler):
    """The library's phase messages as ``phase`` events."""

    def __init__(self, outbox: Any) -> None:
        super().__init__(logging.INFO)
        self.outbox = outbox

    def emit(self, record: logging.LogRecord) -> None:
        try:
            self.outbox.put({"kind": "phase", "text": record.getMessage()[:300]})
        except Exception:  # pragma: no cover - a closed queue at shutdown
            pass


#: The warm-up, in order: each design is heated one step unless a job is already waiting.
WARM_STAGES = (("filament", WARM_DESIGN), ("lattice", WARM_LATTICE))


class _JobWaiting(Exception):
    """A job arrived during the warm-up: the warm-up stops and the job runs."""


def _warm(inbox: Any) -> tuple[list[str], list[Any]]:
    """Heat the :data:`WARM_STAGES` designs until a job arrives on ``inbox``.

    A job that arrives during the warm-up does not wait for it: between the stages, and at a
    stage's printed state (before its heating step, where the kernels load), the inbox is
    looked at and the warm-up stops there. The job then loads the kernels it needs itself, as
    a worker without warm-up would.

    Returns
    -------
    warmed
        Names of the stages heated to their end.
    waiting
        What stopped the warm-up, taken from ``inbox`` (a job, or ``None`` to end the worker);
        empty if the warm-up ran to its end.
    """
    from rotomorph.io.designfile import parse_design
    from rotomorph.simulate.design import StepReport, simulate_design

    waiting: list[Any] = []

    def look() -> None:
        try:
            waiting.append(inbox.get_nowait())
        except queue.Empty:
            return
        raise _JobWaiting

    def on_step(report: StepReport) -> None:
        if report.step == 0:
            look()

    warmed: list[str] = []
    try:
        for name, design in WARM_STAGES:
            look()
            simulate_design(parse_design(dict(design)), steps=1, on_step=on_step)
            warmed.append(name)
    except _JobWaiting:
        pass
    return warmed, waiting


def _topology(design: Any) -> dict[str, Any]:
    """The network a simulation of ``design`` reports steps on (as ``describe_run`` lays it)."""
    if design.lattice is not None:
        lattice = design.lattice.to_lattice()
        net = lattice.network
        edges = np.asarray(net.edges, dtype=np.int64)
        return {
            "kind": "topology",
            "edges": edges,
            "radius": np.full(len(edges), float(lattice.radius)),
            "active_fraction": np.full(len(edges), float(lattice.active_fraction)),
            "printed": np.asarray(net.nodes, dtype=float)
            + np.asarray(design.lattice.origin, dtype=float),
            "chains": [],
            "units": [[0, int(net.n_nodes)]],
            "contact": design.contact is not None,
            "design_name": design.name,
        }
    programs = [f.to_program() for f in design.filaments]
    sizes = [len(p.points) for p in programs]
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(int)
    edges = np.concatenate(
        [
            np.stack([np.arange(n - 1), np.arange(1, n)], axis=1) + o
            for n, o in zip(sizes, starts[:-1], strict=True)
        ]
    )
    return {
        "kind": "topology",
        "edges": edges.astype(np.int64),
        "radius": np.concatenate(
            [np.full(n - 1, p.radius) for n, p in zip(sizes, programs, strict=True)]
        ),
        "active_fraction": np.concatenate(
            [np.full(n - 1, p.active_fraction) for n, p in zip(sizes, programs, strict=True)]
        ),
        "printed": np.concatenate([np.asarray(p.points, dtype=float) for p in programs]),
        "chains": [
            {"name": f.name or f"filament {i}", "start": int(a), "stop": int(b)}
            for i, (f, a, b) in enumerate(
                zip(design.filaments, starts[:-1], starts[1:], strict=True)
            )
        ],
        "units": [[int(a), int(b)] for a, b in itertools.pairwise(starts)],
        "contact": design.contact is not None,
        "design_name": design.name,
    }


def _printed_normals(design: Any) -> list[np.ndarray]:
    """Interface normals toward the active half of each unit's segments as printed."""
    if design.lattice is not None:
        from rotomorph.lattice.model import interface_normals

        return [np.asarray(interface_normals(design.lattice.to_lattice()), dtype=float)]
    return [np.asarray(f.to_program().interface_normals, dtype=float) for f in design.filaments]


def _simulate(job: dict[str, Any], outbox: Any) -> None:
    from rotomorph.io.designfile import parse_design
    from rotomorph.simulate.design import StepReport, simulate_design
    from rotomorph.simulate.outputs import run_line, write_run_results
    from rotomorph.simulate.run_data import describe_run

    design = parse_design(job["design"])
    printed = _printed_normals(design)
    outbox.put({**_topology(design), "normals": np.concatenate(printed).astype(np.float32)})
    angles: dict[int, np.ndarray] = {}

    def on_step(report: StepReport) -> None:
        m1, m2 = report.state.material_directors()
        if report.step == 0 or report.unit not in angles:  # the printed state: the sides' angle
            n0 = printed[report.unit]
            angles[report.unit] = np.arctan2(
                np.einsum("ij,ij->i", n0, m2), np.einsum("ij,ij->i", n0, m1)
            )
        beta = angles[report.unit][:, None]
        normals = np.cos(beta) * m1 + np.sin(beta) * m2
        outbox.put(
            {
                "kind": "step",
                "unit": report.unit,
                "units": report.units,
                "step": report.step,
                "steps": report.steps,
                "value": report.value,
                "ramp": report.ramp,
                "positions": report.positions.astype(np.float32),
                "normals": normals.astype(np.float32),
                "stable": report.stable,
                "residual": report.residual,
                "max_axial_strain": report.max_axial_strain,
            }
        )

    sim = simulate_design(design, steps=int(job["steps"]), on_step=on_step)
    outbox.put({"kind": "phase", "text": "describing the run and writing its files"})
    results = describe_run(sim)
    folder = Path(job["folder"])
    write_run_results(results, folder, movie=False)  # as `rotomorph simulate --no-movie`
    outbox.put({"kind": "done", "folder": str(folder), "line": run_line(results)})


def _inverse(job: dict[str, Any], outbox: Any) -> None:
    """``rotomorph inverse TARGET -o DESIGN`` on the target text, in the job's folder."""
    from rotomorph.inverse.run import inverse_file
    from rotomorph.io.tomlfile import decode_toml_bytes

    folder = Path(job["folder"])
    folder.mkdir(parents=True)
    target = folder / "target.toml"
    target.write_bytes(job["target"])

    def progress(iteration: int, value: float) -> None:
        outbox.put({"kind": "iteration", "iteration": int(iteration), "objective": float(value)})

    design = folder / "design.toml"
    line = inverse_file(target, design, progress)  # "wrote DESIGN and FOLDER/: summary"
    data = decode_toml_bytes(design.read_bytes(), design.name)
    outbox.put({"kind": "done", "design": data, "line": line.partition("/: ")[2] or line})


def _error(err: BaseException) -> dict[str, Any]:
    """The CLI's one-line message and exit class of ``err`` (rotomorph.cli._main's mapping)."""
    from rotomorph.errors import (
        ConvergenceError,
        GcodeParseError,
        InvalidParameterError,
        MachineLimitError,
        RotomorphError,
    )

    if isinstance(err, InvalidParameterError | GcodeParseError):
        return {"kind": "error", "message": str(err), "bad_input": True}
    if isinstance(err, ConvergenceError):
        return {"kind": "error", "message": f"solver: {err}", "bad_input": False}
    if isinstance(err, MachineLimitError):
        return {"kind": "error", "message": f"machine limits: {err}", "bad_input": True}
    if isinstance(err, RotomorphError):
        return {"kind": "error", "message": str(err), "bad_input": False}
    tail = traceback.format_exception_only(type(err), err)[-1].strip()
    return {"kind": "error", "message": f"internal error: {tail}", "bad_input": False}


def run_worker(inbox: Any, outbox: Any, prewarm: bool = True) -> None:
    """Main loop of a worker process: warm up, then run jobs from ``inbox`` until ``None``.

    Parameters
    ----------
    inbox, outbox
        The queues of jobs (dicts; ``None`` ends the loop) and of events.
    prewarm
        Heat the warm-up designs first (:func:`_warm`), so that a lattice's first step comes
        without compiling or loading kernels; a job that arrives meanwhile stops the warm-up.
    """
    log = logging.getLogger("rotomorph.progress")
    log.setLevel(logging.INFO)
    log.addHandler(_Phases(outbox))
    warmed: list[str] = []
    waiting: list[Any] = []
    if prewarm:
        try:
            warmed, waiting = _warm(inbox)
        except Exception as err:  # a failed warm-up only costs the first job's speed
            outbox.put({"kind": "phase", "text": f"warm-up failed: {type(err).__name__}"})
    outbox.put({"kind": "ready", "warmed": warmed})
    while True:
        job = waiting.pop() if waiting else inbox.get()
        if job is None:
            return
        try:
            if job["kind"] == "simulate":
                _simulate(job, outbox)
            elif job["kind"] == "inverse":
                _inverse(job, outbox)
            else:
                outbox.put({"kind": "error", "message": f"unknown job {job['kind']!r}"})
        except BaseException as err:  # reported; the worker stays up for the next job
            outbox.put(_error(err))
            if isinstance(err, KeyboardInterrupt | SystemExit):
                return
