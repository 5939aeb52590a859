"""One self-describing HDF5 file per run, plus a ``summary.json`` (DESIGN section 7).

Layout (format ``rotomorph.results``, version 2)::

    /                       attrs: format, format_version, design (JSON), metadata (JSON),
                                   physical ("yes" | "no" | "unknown"), physical_reason
    /topology/edges         (E, 2) int64       segment end-node indices
    /topology/branch        (N,)   bool        branch-node flags
    /steps/positions        (S, N, 3) float64  attrs: units = "mm"
    /steps/scalars/<name>   (S,)   float64     attrs: units  (actuation, energy, ...)
    /steps/fields/<name>    (S, ...) float64   attrs: units  (per-node or per-edge arrays)
    /static/<name>          (N,...) or (E,...) attrs: units  (arrays that do not change over
                                               the ramp: arc length, filament id, radius, ...)
    /programs/<k>/<name>    print program k:   points (mm), speed (mm/s), nozzle_angle (rad);
                                               attrs: name, radius (mm), active_fraction,
                                               active_material, passive_material, layer

Every dataset carries a ``units`` attribute; ``"1"`` means dimensionless. Files are written
atomically (:mod:`rotomorph.io.atomic`). Version-1 files (no ``static``/``programs``) are read
with those empty.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from enum import Enum
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from rotomorph._display import compact_display
from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path, atomic_write_text

__all__ = [
    "DEFAULT_UNITS",
    "FORMAT",
    "FORMAT_VERSION",
    "PROGRAM_ATTRS",
    "PROGRAM_UNITS",
    "RunResults",
    "program_record",
    "read_results",
    "read_summary",
    "summarize",
    "to_jsonable",
    "write_results",
    "write_summary",
]

FORMAT = "rotomorph.results"
FORMAT_VERSION = 2

#: Units of the usual per-step scalars; any other name needs an entry in ``units``.
DEFAULT_UNITS: Mapping[str, str] = {
    "actuation": "1",
    "temperature": "degC",
    "energy": "N*mm",
    "iterations": "1",
    "residual": "1",
    "area_ratio": "1",
    "edge_strain": "1",
    "gaussian_sign": "1",
    "gaussian_curvature": "1/mm^2",
    "characteristic_curvature": "1/mm",
    "end_to_end_ratio": "1",
    "converged": "1",
    "stable": "1",
    "lowest_eigenvalue": "N/mm^2",
    "min_clearance": "1",
    "max_axial_strain": "1",
    "stack_overlaps": "1",
    "directors": "1",
    "active_normal": "1",
    "twist": "1/mm",
    "curvature": "1/mm",
    "arc_length": "mm",
    "filament_id": "1",
    "radius": "mm",
    "interface_angle": "rad",
    "active_fraction": "1",
    "lattice_edge": "1",
}

#: Units of the arrays of a stored print program.
PROGRAM_UNITS: Mapping[str, str] = {"points": "mm", "speed": "mm/s", "nozzle_angle": "rad"}
#: Scalar attributes of a stored print program (name → unit, ``""`` for text).
PROGRAM_ATTRS: Mapping[str, str] = {
    "name": "",
    "radius": "mm",
    "active_fraction": "1",
    "active_material": "",
    "passive_material": "",
    "layer": "1",
}


@compact_display()
@dataclass(frozen=True, eq=False)
class RunResults:
    """Everything stored for one run (arrays are read-only).

    Attributes
    ----------
    design
        The resolved design (parsed from its JSON attribute).
    edges
        ``(E, 2)`` segment end-node indices.
    branch
        ``(N,)`` branch-node flags.
    positions
        ``(S, N, 3)`` node positions per actuation step (mm).
    scalars
        Per-step scalars by name, each ``(S,)``.
    fields
        Per-step arrays by name, each ``(S, ...)``.
    units
        Unit of every scalar and field by name, and of ``"positions"``.
    metadata
        Free-form run information (versions, run id, timings, the physical-state verdict),
        JSON-compatible.
    static
        Arrays that do not change over the ramp, by name: per node ``(N, ...)`` or per segment
        ``(E, ...)`` (arc length, filament id, radius, interface angle, ...).
    programs
        The print programs: each a mapping with arrays ``points`` ``(n, 3)`` mm, ``speed``
        ``(n,)`` mm/s, ``nozzle_angle`` ``(n,)`` rad and the scalars of
        :data:`PROGRAM_ATTRS`.
    """

    design: Mapping[str, Any]
    edges: IntArray
    branch: BoolArray
    positions: FloatArray
    scalars: Mapping[str, FloatArray]
    fields: Mapping[str, FloatArray] = field(default_factory=dict)
    units: Mapping[str, str] = field(default_factory=dict)
    metadata: Mapping[str, Any] = field(default_factory=dict)
    static: Mapping[str, np.ndarray] = field(default_factory=dict)
    programs: tuple[Mapping[str, Any], ...] = ()

    @property
    def n_steps(self) -> int:
        """Number of stored actuation steps S."""
        return int(self.positions.shape[0])

    def step_labels(self) -> list[str]:
        """One label per step for titles: temperature (°C), else actuation x, else the index."""
        sc = self.scalars
        if "temperature" in sc:
            return [f"T = {t:.0f} °C" for t in sc["temperature"]]
        if "actuation" in sc:
            return [f"x = {x:.2f}" for x in sc["actuation"]]
        return [f"step {k}" for k in range(self.n_steps)]


def to_jsonable(value: Any) -> Any:
    """Convert numpy scalars/arrays, paths, enums and tuples into JSON types; NaN/inf → None."""
    if isinstance(value, Enum):
        return to_jsonable(value.value)
    if isinstance(value, Mapping):
        return {str(k): to_jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [to_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return to_jsonable(value.tolist())
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value)
    if isinstance(value, (float, np.floating)):
        return float(value) if math.isfinite(value) else None
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if value is None or isinstance(value, str):
        return value
    raise InvalidParameterError(
        "value", f"cannot store {type(value).__name__} as JSON; convert it to numbers or text"
    )


def _dumps(value: Any) -> str:
    return json.dumps(to_jsonable(value), sort_keys=True, allow_nan=False)


def _check_name(kind: str, name: str) -> None:
    if not name or "/" in name or name.startswith("."):
        raise InvalidParameterError(kind, f"name {name!r} must be non-empty without '/'")


def _validate(
    edges: Any, branch: Any, positions: Any, scalars: Mapping[str, Any], fields: Mapping
) -> tuple[IntArray, BoolArray, FloatArray, dict[str, FloatArray], dict[str, FloatArray]]:
    pos = np.asarray(positions, dtype=float)
    if pos.ndim == 2:
        pos = pos[None]
    if pos.ndim != 3 or pos.shape[2] != 3 or pos.shape[0] < 1:
        raise InvalidParameterError(
            "positions", f"must have shape (steps, N, 3) in mm; got {np.shape(positions)}"
        )
    steps, n = pos.shape[:2]
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) and (e.min() < 0 or e.max() >= n):
        raise InvalidParameterError("edges", f"indices must lie in [0, {n - 1}]")
    b = np.zeros(n, dtype=bool) if branch is None else np.asarray(branch, dtype=bool)
    if b.shape != (n,):
        raise InvalidParameterError("branch", f"must have one flag per node ({n}); got {b.shape}")
    out_s = {}
    for name, value in scalars.items():
        _check_name("scalars", name)
        v = np.asarray(value, dtype=float).reshape(-1)
        if v.shape != (steps,):
            raise InvalidParameterError(
                f"scalars[{name!r}]", f"must have one value per step ({steps}); got {v.size}"
            )
        out_s[name] = v
    out_f = {}
    for name, value in fields.items():
        _check_name("fields", name)
        v = np.asarray(value, dtype=float)
        if v.ndim < 1 or v.shape[0] != steps:
            raise InvalidParameterError(
                f"fields[{name!r}]", f"must have a leading step axis of {steps}; got {v.shape}"
            )
        out_f[name] = v
    return e, b, pos, out_s, out_f


def write_results(
    path: str | os.PathLike[str],
    *,
    design: Mapping[str, Any] | str,
    edges: IntArray,
    branch: BoolArray | None,
    positions: FloatArray,
    scalars: Mapping[str, Any],
    fields: Mapping[str, Any] | None = None,
    units: Mapping[str, str] | None = None,
    metadata: Mapping[str, Any] | None = None,
    static: Mapping[str, Any] | None = None,
    programs: Sequence[Mapping[str, Any]] = (),
) -> Path:
    """Write one run's results to an HDF5 file atomically and return its path.

    Parameters
    ----------
    path
        Destination (``.h5``); its folder must exist.
    design
        The resolved design as a JSON-compatible mapping, or as a JSON string.
    edges
        ``(E, 2)`` segment end-node indices (e.g. ``network.edges``).
    branch
        ``(N,)`` branch flags (e.g. ``network.branch``); ``None`` stores all False.
    positions
        ``(S, N, 3)`` node positions per actuation step (mm); ``(N, 3)`` is one step.
    scalars
        Per-step scalars by name, each of length S (NaN allowed for a failed step).
    fields
        Per-step arrays by name, each with leading axis S (e.g. ``(S, N)`` curvature change).
    units
        Units by name; names in :data:`DEFAULT_UNITS` may be omitted, any other is required.
    metadata
        JSON-compatible run information; its ``physical`` entry (``{"verdict": "yes" | "no" |
        "unknown", "reason": ...}``) is also written as root attributes.
    static
        Arrays without a step axis by name (per node or per segment); units as for fields.
    programs
        Print programs as mappings (see :class:`RunResults`), e.g. from
        :func:`program_record`.

    Raises
    ------
    InvalidParameterError
        Inconsistent shapes, a name without a unit, or a value that is not JSON-compatible.
    """
    fields = dict(fields or {})
    e, b, pos, sc, fl = _validate(edges, branch, positions, scalars, fields)
    all_units = {"positions": "mm", **DEFAULT_UNITS, **dict(units or {})}
    st = _validate_static(static or {}, len(b), len(e))
    progs = [_validate_program(k, p) for k, p in enumerate(programs)]
    for name in [*sc, *fl, *st]:
        if name not in all_units:
            raise InvalidParameterError(
                "units", f"give a unit for {name!r} (use '1' for dimensionless)"
            )
    design_json = design if isinstance(design, str) else _dumps(design)
    try:
        json.loads(design_json)
    except json.JSONDecodeError as err:
        raise InvalidParameterError("design", f"is not valid JSON: {err}") from err
    with atomic_path(path) as tmp, h5py.File(tmp, "w") as h5:
        h5.attrs["format"] = FORMAT
        h5.attrs["format_version"] = FORMAT_VERSION
        h5.attrs["design"] = design_json
        h5.attrs["metadata"] = _dumps(metadata or {})
        verdict = dict((metadata or {}).get("physical") or {})
        h5.attrs["physical"] = str(verdict.get("verdict", "unknown"))
        h5.attrs["physical_reason"] = str(verdict.get("reason", "not assessed"))
        topo = h5.create_group("topology")
        topo.create_dataset("edges", data=e)
        topo.create_dataset("branch", data=b)
        steps = h5.create_group("steps")
        ds = steps.create_dataset("positions", data=pos, compression="gzip", shuffle=True)
        ds.attrs["units"] = all_units["positions"]
        g = steps.create_group("scalars")
        for name, value in sc.items():
            g.create_dataset(name, data=value).attrs["units"] = all_units[name]
        g = steps.create_group("fields")
        for name, value in fl.items():
            d = g.create_dataset(name, data=value, compression="gzip", shuffle=True)
            d.attrs["units"] = all_units[name]
        g = h5.create_group("static")
        for name, value in st.items():
            d = g.create_dataset(name, data=value)
            d.attrs["units"] = all_units[name]
        g = h5.create_group("programs")
        for k, prog in enumerate(progs):
            pg = g.create_group(f"{k:04d}")
            for name, unit in PROGRAM_UNITS.items():
                pg.create_dataset(name, data=prog[name]).attrs["units"] = unit
            for name, unit in PROGRAM_ATTRS.items():
                pg.attrs[name] = prog[name]
                if unit:
                    pg.attrs[f"{name}_units"] = unit
    return Path(path)


def _validate_static(static: Mapping[str, Any], n: int, e: int) -> dict[str, np.ndarray]:
    out = {}
    for name, value in static.items():
        _check_name("static", name)
        v = np.asarray(value)
        v = v.astype(np.int64) if v.dtype.kind in "iub" else v.astype(float)
        if v.ndim < 1 or v.shape[0] not in (n, e):
            raise InvalidParameterError(
                f"static[{name!r}]", f"needs one row per node ({n}) or segment ({e}); got {v.shape}"
            )
        out[name] = v
    return out


def _validate_program(k: int, prog: Mapping[str, Any]) -> dict[str, Any]:
    out: dict[str, Any] = {}
    missing = [x for x in [*PROGRAM_UNITS, *PROGRAM_ATTRS] if x not in prog]
    if missing:
        raise InvalidParameterError(f"programs[{k}]", f"missing {', '.join(missing)}")
    pts = np.asarray(prog["points"], dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InvalidParameterError(f"programs[{k}].points", f"must be (n, 3) mm; got {pts.shape}")
    out["points"] = pts
    for name in ("speed", "nozzle_angle"):
        v = np.asarray(prog[name], dtype=float).reshape(-1)
        if v.shape != (len(pts),):
            raise InvalidParameterError(f"programs[{k}].{name}", f"needs {len(pts)} values")
        out[name] = v
    for name, unit in PROGRAM_ATTRS.items():
        out[name] = str(prog[name]) if not unit else float(prog[name])
    return out


def program_record(program: Any, name: str = "") -> dict[str, Any]:
    """The stored form of a :class:`~rotomorph.design.program.PrintProgram` (see
    :class:`RunResults`)."""
    return {
        "name": name,
        "points": np.asarray(program.points, dtype=float),
        "speed": np.asarray(program.speed, dtype=float),
        "nozzle_angle": np.asarray(program.nozzle_angle, dtype=float),
        "radius": float(program.radius),
        "active_fraction": float(program.active_fraction),
        "active_material": str(program.active_material),
        "passive_material": str(program.passive_material),
        "layer": float(getattr(program, "layer", 0)),
    }


def read_results(path: str | os.PathLike[str]) -> RunResults:
    """Read and validate a file written by :func:`write_results`, with bounded memory
    (:func:`rotomorph.io.results_read.read_results`: what is checked and the limits).

    Raises
    ------
    InvalidParameterError
        If the file is not a rotomorph results file, has a newer format version, or is
        damaged (one line naming the object in the file).
    OSError
        The file cannot be opened as HDF5.
    """
    from rotomorph.io.results_read import read_results as read_checked

    return read_checked(path)


def summarize(results: RunResults) -> dict[str, Any]:
    """A JSON-compatible summary: the physical-state verdict, per-filament results, sizes,
    units and the first and end-of-ramp value of every scalar.

    ``physical`` is ``metadata["physical"]`` when the run assessed its states, else
    ``{"verdict": "unknown", ...}``; the last state is called ``end_of_ramp``, not "final":
    it is a result only where ``physical.verdict`` is ``"yes"``.
    """
    meta = to_jsonable(results.metadata)
    physical = meta.get("physical") or {"verdict": "unknown", "reason": "not assessed"}
    out = {
        "format": FORMAT,
        "physical": physical,
        "n_steps": results.n_steps,
        "n_nodes": int(results.positions.shape[1]),
        "n_edges": len(results.edges),
        "end_of_ramp": {k: to_jsonable(v[-1]) for k, v in results.scalars.items()},
        "initial": {k: to_jsonable(v[0]) for k, v in results.scalars.items()},
        "units": _summary_units(results),
        "metadata": meta,
    }
    if "filaments" in meta:
        out["filaments"] = meta["filaments"]
    # outside the range the materials law was calibrated on (rotomorph.simulate.extrapolation)
    out["extrapolated"] = bool(meta.get("extrapolated", False))
    out["extrapolation"] = list(meta.get("extrapolation") or [])
    return out


def _summary_units(results: RunResults) -> dict[str, str]:
    """Units of every array of ``results``, as :func:`write_results` stores them (the usual
    scalars' units are defaults, so a run described in memory lists them too)."""
    units = {"positions": "mm", **dict(results.units)}
    for group in (results.scalars, results.fields, results.static):
        for name in group:
            if name not in units and name in DEFAULT_UNITS:
                units[name] = DEFAULT_UNITS[name]
    return units


def write_summary(path: str | os.PathLike[str], summary: Mapping[str, Any]) -> Path:
    """Write ``summary`` as indented, key-sorted strict JSON (NaN/inf → null), atomically."""
    text = json.dumps(to_jsonable(summary), indent=2, sort_keys=True, allow_nan=False)
    return atomic_write_text(path, text + "\n")


def read_summary(path: str | os.PathLike[str]) -> dict[str, Any]:
    """Read a ``summary.json``."""
    return json.loads(Path(path).read_text(encoding="utf-8"))
