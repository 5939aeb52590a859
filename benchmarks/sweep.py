"""Benchmark: throughput and per-run overhead of the sweep runner (JSON lines).

A 200-run filament sweep (composite 10 mm filaments, 20 rotation rates × 10 speeds, rod solver,
3 heating steps, 0.5 mm vertices) is run into fresh folders:

``sweep-local``
    the default local process pool (2 workers), started and warmed before timing; its start-up
    (fork server, imports, kernel loading) is reported separately as ``startup_s`` (what
    ``rotomorph sweep`` adds once per command).
``sweep-dask``
    a 2-worker :class:`dask.distributed.LocalCluster` (processes, one thread each), warmed
    before timing (a cluster is long-lived); also carries ``speedup_2_workers``: its runs/s over
    the same sweep on a 1-worker cluster.

``overhead_per_run_ms`` = (wall × workers − Σ single-run times) / runs, where a single-run time
is the run's ``wall_time_s`` measured on its worker around the computation.
``submitter_cpu_per_run_ms`` is the CPU time of this process (planning, the Dask scheduler and
client threads of a LocalCluster, storing records) per run: on a 2-core machine it competes with
the two workers, which is what bounds ``speedup_2_workers`` below 2. Short runs are batched
(``run_sweep``'s adaptive ``chunk``), which is what keeps it small. ``loadavg`` is the 1-minute
load average before and after each case: other work on the machine slows the workers, and the
speed-up is only meaningful on an otherwise idle machine.

Run: ``python benchmarks/sweep.py [--runs 200]``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

from rotomorph.sweep import local_executor, parse_sweep, run_sweep


def benchmark_sweep(runs: int):
    n_w = 20
    n_v = max(1, runs // n_w)
    return parse_sweep(
        {
            "schema_version": 1,
            "name": "benchmark",
            "outputs": ["end_to_end_ratio", "morphology"],
            "design": {
                "schema_version": 1,
                "filaments": [
                    {
                        "speed": 3.0,
                        "rotation_number": 0.25,
                        "active_fraction": 0.5,
                        "spacing": 0.5,
                        "segments": [{"kind": "line", "length": 10.0}],
                    }
                ],
            },
            "settings": {"steps": 3},
            "parameters": [
                {
                    "path": "filaments[0].rotation_number",
                    "range": {"start": 0.05, "stop": 2.0, "num": n_w, "log": True},
                },
                {
                    "path": "filaments[0].speed",
                    "range": {"start": 0.5, "stop": 3.0, "num": n_v},
                },
            ],
        }
    )


def _case(name: str, sweep, n_workers: int, **kw) -> dict:
    load0 = os.getloadavg()[0]
    with tempfile.TemporaryDirectory() as tmp:
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        t0 = time.perf_counter()
        result = run_sweep(sweep, Path(tmp) / "out", **kw)
        wall = time.perf_counter() - t0
        r1 = resource.getrusage(resource.RUSAGE_SELF)
    submitter = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    table = result.table
    n = table.num_rows
    solve = sum(table.column("wall_time_s").to_pylist())
    statuses = table.column("status").to_pylist()
    return {
        "case": name,
        "runs": n,
        "workers": n_workers,
        "ok": statuses.count("ok"),
        "wall_s": round(wall, 3),
        "runs_per_s": round(n / wall, 3),
        "sum_run_s": round(solve, 3),
        "overhead_per_run_ms": round(1e3 * (wall * n_workers - solve) / n, 2),
        "submitter_cpu_per_run_ms": round(1e3 * submitter / n, 2),
        "loadavg": [round(load0, 2), round(os.getloadavg()[0], 2)],
        "cpus": os.cpu_count(),
    }


def _warm() -> None:
    import rotomorph.sweep._warm  # noqa: F401


def _dask_case(sweep, workers: int) -> dict:
    from distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        client.run(_warm)
        return _case(f"sweep-dask-{workers}", sweep, workers, executor=client)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=200, help="runs per sweep")
    args = parser.parse_args(argv)
    sweep = benchmark_sweep(args.runs)
    _warm()  # compile and cache the kernels once, outside every timing
    t0 = time.perf_counter()
    with local_executor(2) as pool:
        for f in [pool.submit(os.getpid) for _ in range(4)]:  # start and warm both workers
            f.result()
        startup = time.perf_counter() - t0
        local = _case("sweep-local", sweep, 2, executor=pool)
    local.update(startup_included=False, startup_s=round(startup, 3))
    sys.stdout.write(json.dumps(local) + "\n")
    two = _dask_case(sweep, 2)
    one = _dask_case(sweep, 1)
    two.update(
        case="sweep-dask",
        startup_included=False,
        speedup_2_workers=round(two["runs_per_s"] / one["runs_per_s"], 3),
        one_worker_runs_per_s=one["runs_per_s"],
        one_worker_overhead_per_run_ms=one["overhead_per_run_ms"],
    )
    sys.stdout.write(json.dumps(two) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
