"""Short runs travel to the executor in batches; the table does not depend on the batching."""

from __future__ import annotations

import concurrent.futures as cf

import pytest

from conftest import without_wall_time
from rotomorph.errors import InvalidParameterError
from rotomorph.sweep import load_sweep, run_sweep
from rotomorph.sweep.runner import _Batching, evaluate_batch, executor_slots


class CountingExecutor(cf.ThreadPoolExecutor):
    """A thread pool that remembers how many runs each submitted task holds."""

    def __init__(self, workers: int) -> None:
        super().__init__(max_workers=workers)
        self.task_sizes: list[int] = []

    def submit(self, fn, /, *args, **kwargs):  # type: ignore[override]
        assert fn is evaluate_batch
        self.task_sizes.append(len(args[1]))
        return super().submit(fn, *args, **kwargs)


def test_adaptive_batches_follow_the_measured_run_time():
    b = _Batching(slots=2, target_s=0.5, limit=32)
    assert b.size(100) == 1  # nothing measured yet: single runs
    b.runs, b.seconds = 4, 0.2  # 50 ms per run -> 10 runs per task
    assert b.size(1000) == 10
    assert b.size(12) == 3  # near the end: a fair share of what is left (12 / (2 x 2))
    assert b.size(1) == 1
    b.runs, b.seconds = 1, 5.0  # long runs go one per task
    assert b.size(1000) == 1
    b.runs, b.seconds = 10, 1e-6  # very short runs: capped
    assert b.size(10_000) == 32
    assert _Batching(slots=2, fixed=7).size(3) == 7


def test_batched_and_single_run_tasks_give_the_same_table(local_result, sweep_file, tmp_path):
    sweep = load_sweep(sweep_file)
    tables = {}
    for chunk in (1, 4, None):
        with CountingExecutor(2) as pool:
            result = run_sweep(sweep, tmp_path / f"chunk{chunk}", executor=pool, chunk=chunk)
        sizes = pool.task_sizes
        assert sum(sizes) == 12  # the 3 points with a negative speed need no worker
        if chunk is not None:
            assert max(sizes) <= chunk and len(sizes) == -(-12 // chunk)
        else:  # one probe per worker first, then batches of the measured runs
            assert sizes[:2] == [1, 1]
        tables[chunk] = without_wall_time(result.table)
    assert tables[1] == tables[4] == tables[None] == without_wall_time(local_result.table)


def test_executor_slots_and_bad_chunks(sweep_file, tmp_path):
    with cf.ThreadPoolExecutor(max_workers=3) as pool:
        assert executor_slots(pool) == 3
    for bad in (0, -2, 1.5, True, "4"):
        with pytest.raises(InvalidParameterError, match="chunk"):
            run_sweep(load_sweep(sweep_file), tmp_path / "bad", chunk=bad)  # type: ignore[arg-type]
