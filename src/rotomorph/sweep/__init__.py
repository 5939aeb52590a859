"""Parameter studies: sweep files, deterministic run ids, resumable runs on any Executor.

Typical use::

    from rotomorph.sweep import load_sweep, run_sweep

    sweep = load_sweep("examples/sweeps/janus_curvature_speed.toml")
    result = run_sweep(sweep, "out/janus")          # local process pool
    result.table.to_pandas()                         # one row per point

With Dask: ``run_sweep(sweep, "out", executor=client)`` or ``scheduler="tcp://HOST:PORT"``.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from rotomorph.sweep.run import RunOutcome, RunSpec, execute_run, resolve_run
    from rotomorph.sweep.runner import (
        SweepProgress,
        SweepResult,
        local_executor,
        plan_sweep,
        run_sweep,
    )
    from rotomorph.sweep.sampling import sample_points
    from rotomorph.sweep.spec import Sweep, load_sweep, parse_sweep, sweep_schema
    from rotomorph.sweep.table import read_table

#: Public name -> module that defines it, imported on first access: the command line builds
#: its ``sweep`` parser from :mod:`rotomorph.sweep.command` without paying for the runner,
#: designs and solver (~2 s) on every command.
_LAZY = {
    **dict.fromkeys(("RunOutcome", "RunSpec", "execute_run", "resolve_run"), "run"),
    **dict.fromkeys(
        ("SweepProgress", "SweepResult", "local_executor", "plan_sweep", "run_sweep"), "runner"
    ),
    "sample_points": "sampling",
    **dict.fromkeys(("Sweep", "load_sweep", "parse_sweep", "sweep_schema"), "spec"),
    "read_table": "table",
}


def __getattr__(name: str) -> Any:
    if name in _LAZY:
        value = getattr(importlib.import_module(f"rotomorph.sweep.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'rotomorph.sweep' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))


__all__ = [
    "RunOutcome",
    "RunSpec",
    "Sweep",
    "SweepProgress",
    "SweepResult",
    "execute_run",
    "load_sweep",
    "local_executor",
    "parse_sweep",
    "plan_sweep",
    "read_table",
    "resolve_run",
    "run_sweep",
    "sample_points",
    "sweep_schema",
]
