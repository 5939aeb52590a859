"""The results table of a sweep: one row per point, written as Parquet (pyarrow).

Columns, in order:

``index`` (int64)
    Position of the point in the sampling order (0-based).
``run_id`` (string)
    The run's id (:mod:`rotomorph.sweep.run`); points resolving to the same design share it.
one column per parameter
    Named by its ``name`` or its path; float64, int64, bool or string.
one column per output
    Named as in ``outputs``; typed by the metric (float64, int64, string, bool); null when the
    run did not succeed or the metric does not apply (e.g. ``helix_pitch`` of a straight rod).
``status`` (string)
    ``ok``, ``invalid`` or ``failed``.
``physical`` (bool, nullable), ``physical_reason`` (string)
    The run's physical-state verdict (converged, verified stable, no filament passing through
    another): true, false, or null when a check was not made; and why
    (:mod:`rotomorph.sweep.metrics`). False for runs that did not succeed.
``wall_time_s`` (float64)
    Seconds the run took on its worker (the only column that differs between two executions
    of the same sweep).
``error_type``, ``error_message`` (string), ``error_diagnostics`` (string, JSON)
    Null for ``ok`` runs.
``warnings`` (string, JSON list)
    Warnings the library logged during the run (null if none).

Each field's metadata carries its ``unit``; the schema's metadata carries the sweep's name and
sha256, and the rotomorph version.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from rotomorph.io.atomic import atomic_path
from rotomorph.sweep.metrics import METRICS, is_physical, physical_reason, select_output
from rotomorph.sweep.spec import Sweep

__all__ = ["PARAMETER_UNITS", "TABLE_FILE", "build_table", "read_table", "write_table"]

#: File name of the table in a sweep folder.
TABLE_FILE = "results.parquet"

_ARROW = {"float": "float64", "int": "int64", "str": "string", "bool": "bool_"}

#: Unit of a parameter column by the design field it sets (the last key of its path).
PARAMETER_UNITS = {
    "speed": "mm/s",
    "rotation": "rad/s",
    "rotation_number": "1",
    "active_fraction": "1",
    "length": "mm",
    "radius": "mm",
    "spacing": "mm",
    "amplitude": "mm",
    "wavelength": "mm",
    "layer_height": "mm",
    "flip_length": "mm",
    "angle_deg": "deg",
    "heading_deg": "deg",
    "interface_angle_deg": "deg",
}


def _param_type(values: Sequence[Any]) -> Any:
    import pyarrow as pa

    present = [v for v in values if v is not None]
    if present and all(isinstance(v, bool) for v in present):
        return pa.bool_()
    if present and all(isinstance(v, int) and not isinstance(v, bool) for v in present):
        return pa.int64()
    if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in present):
        return pa.float64()
    return pa.string()


def _output_metric(name: str, scope: str) -> Any:
    base = name.rsplit(".", 1)[-1]
    return next(m for m in METRICS if m.name == base and m.scope == scope)


def build_table(
    sweep: Sweep,
    points: Sequence[Mapping[str, Any]],
    run_ids: Sequence[str],
    records: Mapping[str, Mapping[str, Any]],
) -> Any:
    """The :class:`pyarrow.Table` of a sweep (module docstring).

    Parameters
    ----------
    sweep
        The sweep.
    points
        Its points (:func:`~rotomorph.sweep.sampling.sample_points`).
    run_ids
        The run id of every point.
    records
        Records by run id; points without a record are left out (unfinished).
    """
    import pyarrow as pa

    import rotomorph

    rows = [
        (i, p, records[r])
        for i, (p, r) in enumerate(zip(points, run_ids, strict=True))
        if r in records
    ]
    scope = "lattice" if "lattice" in sweep.design else "filament"
    cols: dict[str, Any] = {}
    fields: list[Any] = []

    def add(name: str, values: list[Any], typ: Any, unit: str = "") -> None:
        cols[name] = pa.array(
            [str(v) if typ == pa.string() and v is not None else v for v in values], type=typ
        )
        fields.append(pa.field(name, typ, metadata={"unit": unit}))

    add("index", [i for i, _, _ in rows], pa.int64())
    add("run_id", [rec["run_id"] for _, _, rec in rows], pa.string())
    for param in sweep.parameters:
        values = [p[param.path] for _, p, _ in rows]
        unit = PARAMETER_UNITS.get(param.path.rsplit(".", 1)[-1], "")
        add(param.column, values, _param_type(values), unit)
    for out in sweep.outputs:
        metric = _output_metric(out, scope)
        values = [select_output(rec["metrics"], out) for _, _, rec in rows]
        if metric.dtype == "float":
            values = [None if v is None else float(v) for v in values]
        add(out, values, getattr(pa, _ARROW[metric.dtype])(), metric.unit)
    add("status", [rec["status"] for _, _, rec in rows], pa.string())
    add(
        "physical",
        [is_physical(rec["metrics"]) if rec["status"] == "ok" else False for _, _, rec in rows],
        pa.bool_(),
    )
    add(
        "physical_reason",
        [
            physical_reason(rec["metrics"]) if rec["status"] == "ok" else "no state computed"
            for _, _, rec in rows
        ],
        pa.string(),
    )
    add("wall_time_s", [float(rec["wall_time_s"]) for _, _, rec in rows], pa.float64(), "s")
    errors = [rec.get("error") or {} for _, _, rec in rows]
    add("error_type", [e.get("type") for e in errors], pa.string())
    add("error_message", [e.get("message") for e in errors], pa.string())
    add(
        "error_diagnostics",
        [json.dumps(e["diagnostics"], sort_keys=True) if e else None for e in errors],
        pa.string(),
    )
    add(
        "warnings",
        [json.dumps(rec["warnings"]) if rec.get("warnings") else None for _, _, rec in rows],
        pa.string(),
    )
    meta = {
        "sweep_name": sweep.name,
        "sweep_sha256": sweep.sha256(),
        "rotomorph_version": rotomorph.__version__,
    }
    return pa.Table.from_arrays(list(cols.values()), schema=pa.schema(fields, metadata=meta))


def write_table(table: Any, path: str | os.PathLike[str]) -> Path:
    """Write ``table`` as Parquet atomically (temporary file, then rename)."""
    import pyarrow.parquet as pq

    with atomic_path(path) as tmp:
        pq.write_table(table, tmp)
    return Path(path)


def read_table(path: str | os.PathLike[str]) -> Any:
    """Read a sweep's Parquet table (a folder means its ``results.parquet``)."""
    import pyarrow.parquet as pq

    p = Path(path)
    return pq.read_table(p / TABLE_FILE if p.is_dir() else p)
