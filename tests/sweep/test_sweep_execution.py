"""Sweeps run the same on any executor, resume after SIGKILL without recomputing, and record
invalid points with their errors."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import without_wall_time
from rotomorph.sweep import load_sweep, plan_sweep, run_sweep
from rotomorph.sweep.store import RunStore

HERE = Path(__file__).resolve().parent
SRC = HERE.parents[1] / "src"


def test_invalid_points_are_recorded_and_the_valid_ones_finish(local_result):
    rows = local_result.table.to_pylist()
    assert len(rows) == 15
    by = {(r["filaments[0].rotation_number"], r["filaments[0].speed"]): r for r in rows}
    for w in (0.0, 0.25, 1.0):
        for v in (0.5, 1.0, 2.0):
            r = by[(w, v)]
            assert r["status"] == "ok", r["error_message"]
            assert 0.0 < r["end_to_end_ratio"] < 1.0
            assert r["morphology"] in ("twisted rod", "helix", "coil")
            assert r["error_type"] is None
        fast = by[(w, 9.0)]
        assert fast["status"] == "invalid"
        assert fast["error_type"] == "MachineLimitError"
        assert "max_feed" in fast["error_message"]
        assert fast["end_to_end_ratio"] is None
        negative = by[(w, -1.0)]
        assert negative["status"] == "invalid"
        assert negative["error_type"] == "InvalidDesignError"
        assert json.loads(negative["error_diagnostics"]) == {"field": "filaments[0].speed"}
    # physics of the sweep: a faster print (higher order) bends more at ω* = 0; rotation
    # straightens the filament (L/L0 grows with ω*)
    assert by[(0.0, 2.0)]["curvature"] > by[(0.0, 0.5)]["curvature"]
    assert by[(0.0, 1.0)]["end_to_end_ratio"] < by[(1.0, 1.0)]["end_to_end_ratio"]


def test_dask_local_cluster_gives_the_same_table(local_result, sweep_file, tmp_path):
    distributed = pytest.importorskip("distributed")
    with (
        distributed.LocalCluster(
            n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        result = run_sweep(load_sweep(sweep_file), tmp_path / "dask", executor=client)
    assert result.progress.ok + result.progress.failed == 15
    assert without_wall_time(result.table) == without_wall_time(local_result.table)


def _records(folder: Path) -> set[str]:
    return set(RunStore(folder).finished()) if (folder / "runs").is_dir() else set()


def test_sigkill_and_restart_recomputes_nothing_and_loses_nothing(
    local_result, sweep_file, tmp_path
):
    folder = tmp_path / "killed"
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(SRC), str(HERE)])}
    script = [sys.executable, str(HERE / "_counting.py"), str(sweep_file), str(folder)]
    log1, log2 = tmp_path / "first.log", tmp_path / "second.log"
    total = len({s.run_id for s in plan_sweep(load_sweep(sweep_file))[1]})

    proc = subprocess.Popen([*script, str(log1)], env=env, start_new_session=True)
    deadline = time.monotonic() + 60
    try:
        # kill once some, not all, of the computed runs are stored (3 invalid ones are stored first)
        while len(_records(folder)) < 6 + 3 and time.monotonic() < deadline:
            time.sleep(0.02)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()
    finished_before = _records(folder)
    assert 6 + 3 <= len(finished_before) < total, "the sweep was not killed half-way"
    assert not (folder / "results.parquet").exists()

    subprocess.run([*script, str(log2)], env=env, check=True, timeout=120)
    second = log2.read_text().split()
    assert not set(second) & finished_before, "a finished run was computed again"
    assert len(second) == len(set(second)) == total - len(finished_before)
    assert _records(folder) == {s.run_id for s in plan_sweep(load_sweep(sweep_file))[1]}
    from rotomorph.sweep import read_table

    assert without_wall_time(read_table(folder)) == without_wall_time(local_result.table)
