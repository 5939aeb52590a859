"""Parameter studies: sweep files, deterministic run ids, resumable runs on any Executor.

Typical use::

    from rotomorph.sweep import load_sweep, run_sweep

    sweep = load_sweep("examples/sweeps/janus_curvature_speed.toml")
    result = run_sweep(sweep, "out/janus")          # local process pool
    result.table.to_pandas()                         # one row per point

With Dask: ``run_sweep(sweep, "out", executor=client)`` or ``scheduler="tcp://HOST:PORT"``.
"""

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
