"""Run a sweep on any ``concurrent.futures.Executor``: resumable, exactly once per run id.

:func:`run_sweep` resolves every point to a :class:`~rotomorph.sweep.run.RunSpec`, drops the
ids already finished in the folder (a set difference, so a restarted sweep only computes what is
missing), submits the rest to an executor and stores each outcome as it arrives
(:class:`~rotomorph.sweep.store.RunStore`), then writes the table. The executor is

* by default a local process pool (``workers`` processes, forked from a server that has already
  imported rotomorph);
* ``scheduler="tcp://HOST:PORT"``: a :class:`dask.distributed.Client` connected to that
  scheduler, through its ``get_executor()``;
* any object with ``get_executor()`` (a Dask ``Client``; e.g. one of a dask-jobqueue
  ``SLURMCluster``) or any ``concurrent.futures.Executor``.

Tasks are submitted as ``executor.submit(evaluate_batch, evaluate, specs)``: short runs are
batched adaptively (about half a second of work per task) so the executor's per-task cost is
paid once per batch; long runs go one per task.
Results travel back to this process, which alone writes the folder (workers need no shared
file system). A failed run is recorded with its error and the sweep goes on.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import json
import logging
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.sweep.executors import local_executor, open_executor, probe_scheduler
from rotomorph.sweep.run import RunOutcome, RunSpec, execute_run, resolve_run
from rotomorph.sweep.sampling import sample_points
from rotomorph.sweep.spec import Sweep
from rotomorph.sweep.store import RunStore
from rotomorph.sweep.table import TABLE_FILE, build_table, write_table

__all__ = [
    "SweepProgress",
    "SweepResult",
    "evaluate_batch",
    "executor_slots",
    "local_executor",
    "plan_sweep",
    "run_sweep",
]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class SweepProgress:
    """Counts reported after every finished run.

    Attributes
    ----------
    total
        Distinct runs of the sweep.
    skipped
        Runs already finished in the folder when the sweep started.
    ok, failed
        Runs finished in this session with status ``ok`` / ``invalid`` or ``failed``.
    """

    total: int
    skipped: int
    ok: int
    failed: int

    @property
    def done(self) -> int:
        """Finished runs, including those found finished."""
        return self.skipped + self.ok + self.failed

    @property
    def remaining(self) -> int:
        """Runs still to compute."""
        return self.total - self.done


@dataclass(frozen=True, eq=False)
class SweepResult:
    """A finished sweep.

    Attributes
    ----------
    folder
        The sweep folder.
    table
        The results table (:mod:`rotomorph.sweep.table`), a :class:`pyarrow.Table`.
    progress
        Final counts.
    wall_time
        Seconds this call took.
    lost
        Runs the executor lost (worker crash), not recorded: run the sweep again to finish them.
    """

    folder: Path
    table: Any
    progress: SweepProgress
    wall_time: float
    lost: tuple[str, ...] = ()

    @property
    def complete(self) -> bool:
        """Every run is finished (ok, invalid or failed)."""
        return self.progress.remaining == 0

    @property
    def table_path(self) -> Path:
        """The Parquet file."""
        return self.folder / TABLE_FILE


def plan_sweep(sweep: Sweep) -> tuple[list[dict[str, Any]], list[RunSpec]]:
    """The sweep's points and one :class:`RunSpec` per point (same order)."""
    points = sample_points(sweep)
    return points, [resolve_run(sweep, p) for p in points]


def _write_plan(store: RunStore, sweep: Sweep) -> None:
    text = json.dumps(sweep.model_dump(mode="json"), indent=2, sort_keys=True)
    atomic_write_text(store.folder / "sweep.json", text + "\n", fsync=store.fsync)


def run_sweep(
    sweep: Sweep,
    folder: str | os.PathLike[str],
    *,
    executor: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
    progress: Callable[[SweepProgress], None] | None = None,
    evaluate: Callable[[RunSpec], RunOutcome] = execute_run,
    max_pending: int = 256,
    fsync: bool = True,
    chunk: int | None = None,
) -> SweepResult:
    """Compute every run of ``sweep`` not yet finished in ``folder`` and write the table.

    Parameters
    ----------
    sweep
        The validated sweep (:func:`~rotomorph.sweep.spec.load_sweep`).
    folder
        Output folder (created if missing); finished runs found there are not recomputed.
    executor
        A ``concurrent.futures.Executor`` or a Dask ``Client`` (its ``get_executor()`` is
        used); the caller keeps ownership (it is not shut down).
    scheduler
        Address of a Dask scheduler (``tcp://HOST:PORT``) to connect to instead.
    workers
        Processes of the default local pool (default: the CPU count).
    progress
        Called with a :class:`SweepProgress` at the start and after every finished run.
    evaluate
        The function computing one run (default :func:`~rotomorph.sweep.run.execute_run`); a
        replacement must be picklable (module-level) and return a :class:`RunOutcome`.
    max_pending
        Most runs submitted and not yet finished at a time.
    fsync
        Flush every record to disk before it counts as finished.
    chunk
        Runs per executor task. Default (``None``): adaptive — the first task per worker
        holds one run; then tasks hold about half a second of work (at most 32 runs, and a
        fair share of what remains near the end), which pays the executor's per-task cost
        (Dask: scheduler and client, about 10 ms of the submitting process's CPU per task)
        once per batch. ``1`` submits every run as its own task. Outcomes are recorded as
        their task returns, so a killed sweep loses at most the unfinished tasks' work,
        never a record.

    Raises
    ------
    InvalidParameterError
        Another sweep holds the folder, the scheduler cannot be reached or does not answer
        as a Dask scheduler within :data:`~rotomorph.sweep.executors.HANDSHAKE_TIMEOUT_S`,
        or ``chunk < 1``.
    """
    if chunk is not None and (isinstance(chunk, bool) or not isinstance(chunk, int) or chunk < 1):
        raise InvalidParameterError("chunk", f"must be an integer >= 1 or None; got {chunk!r}")
    t0 = time.perf_counter()
    if scheduler is not None and executor is None:
        probe_scheduler(scheduler)  # not a Dask scheduler: one line in seconds, no folder made
    points, specs = plan_sweep(sweep)
    unique = {s.run_id: s for s in specs}
    with RunStore(folder, fsync=fsync) as store:
        _write_plan(store, sweep)
        done = set(store.finished(unique))  # trusted records only; damaged ones are redone
        todo = [unique[i] for i in dict.fromkeys(s.run_id for s in specs) if i not in done]
        counts = {"ok": 0, "failed": 0}
        total, skipped = len(unique), len(done)

        def report() -> None:
            if progress is not None:
                progress(SweepProgress(total, skipped, counts["ok"], counts["failed"]))

        def store_outcome(outcome: RunOutcome) -> None:
            store.write(outcome.record, outcome.results)
            counts["ok" if outcome.record["status"] == "ok" else "failed"] += 1
            report()

        report()
        # known-invalid points need no worker
        for spec in [s for s in todo if s.error is not None]:
            store_outcome(evaluate(spec))
        remote = [s for s in todo if s.error is None]
        lost: list[str] = []
        if remote:
            with open_executor(executor, scheduler, workers) as ex:
                lost = _drain(ex, evaluate, remote, store_outcome, max(1, max_pending), chunk)
        records = store.finished(unique)
        table = build_table(sweep, points, [s.run_id for s in specs], records)
        write_table(table, store.folder / TABLE_FILE)
    final = SweepProgress(total, skipped, counts["ok"], counts["failed"])
    return SweepResult(Path(folder), table, final, time.perf_counter() - t0, tuple(lost))


def evaluate_batch(
    evaluate: Callable[[RunSpec], RunOutcome], specs: Sequence[RunSpec]
) -> list[RunOutcome]:
    """Compute several runs in one task (module level, so every executor can pickle it)."""
    return [evaluate(spec) for spec in specs]


def executor_slots(ex: Any) -> int:
    """Runs an executor computes at once: a process pool's workers, a Dask client's threads,
    else the CPU count."""
    client = getattr(ex, "_client", None)  # distributed's ClientExecutor
    if client is not None:
        with contextlib.suppress(Exception):
            return max(1, sum(client.nthreads().values()))
    workers = getattr(ex, "_max_workers", None)  # concurrent.futures pools
    if isinstance(workers, int) and workers > 0:
        return workers
    return os.cpu_count() or 1


@dataclass
class _Batching:
    """How many runs go into one task.

    ``fixed`` (>= 1) is used as given. Otherwise (adaptive) the first ``slots`` tasks are
    single runs; from then on a task holds about ``target_s`` seconds of work (the mean
    single-run time measured so far), at most ``limit`` runs, and near the end of the sweep
    no more than a fair share of what remains, so every worker stays busy to the last run.
    """

    slots: int
    fixed: int | None = None
    target_s: float = 0.5
    limit: int = 32
    runs: int = 0
    seconds: float = 0.0

    def observe(self, outcome: RunOutcome) -> None:
        wall = outcome.record.get("wall_time_s")
        if isinstance(wall, (int, float)) and wall >= 0:
            self.runs += 1
            self.seconds += float(wall)

    def size(self, remaining: int) -> int:
        if self.fixed is not None:
            return self.fixed
        if self.runs == 0:
            return 1
        per_run = max(self.seconds / self.runs, 1e-6)
        wanted = max(1, min(self.limit, int(self.target_s / per_run)))
        fair = max(1, -(-remaining // (2 * self.slots)))
        return min(wanted, fair)


def _drain(
    ex: cf.Executor,
    evaluate: Callable[[RunSpec], RunOutcome],
    specs: Sequence[RunSpec],
    sink: Callable[[RunOutcome], None],
    window: int,
    chunk: int | None = None,
) -> list[str]:
    """Submit ``specs`` in tasks of one or more runs (at most ``window`` runs pending), pass
    outcomes to ``sink`` as their task finishes.

    Short runs are batched (:class:`_Batching`) so the per-task cost of the executor (the
    scheduler, the client, the transfers) is paid once per batch, not once per run.

    Returns the errors of runs the executor lost (a worker died, the pool broke); those runs
    are not recorded, so running the sweep again computes them.
    """
    queue = list(specs)[::-1]  # pop() from the end: submission order is the sweep's order
    pending: dict[cf.Future[list[RunOutcome]], list[RunSpec]] = {}
    lost: list[str] = []
    batching = _Batching(slots=executor_slots(ex), fixed=chunk)
    probes = batching.slots  # single-run tasks submitted before any run time is known

    def in_flight() -> int:
        return sum(len(batch) for batch in pending.values())

    def fill() -> None:
        nonlocal probes
        while queue and in_flight() < window:
            if batching.fixed is None and batching.runs == 0:
                if probes == 0:
                    return  # wait for a measured run before batching
                probes -= 1
            size = min(batching.size(len(queue)), window - in_flight(), len(queue))
            batch = [queue.pop() for _ in range(max(1, size))]
            try:
                pending[ex.submit(evaluate_batch, evaluate, batch)] = batch
            except Exception as err:  # a broken pool refuses new work
                lost.extend(f"{s.run_id[:12]}: {type(err).__name__}: {err}" for s in batch[:1])
                lost.extend(f"{s.run_id[:12]}: not submitted" for s in batch[1:])
                lost.extend(f"{s.run_id[:12]}: not submitted" for s in reversed(queue))
                queue.clear()
                return

    fill()
    while pending:
        finished, _ = cf.wait(pending, return_when=cf.FIRST_COMPLETED)
        for fut in finished:
            batch = pending.pop(fut)
            try:
                outcomes = fut.result()
            except Exception as err:  # the executor, not the run, failed
                for spec in batch:
                    logger.warning("run %s lost: %s: %s", spec.run_id[:12], type(err).__name__, err)
                    lost.append(f"{spec.run_id[:12]}: {type(err).__name__}: {err}")
                continue
            for outcome in outcomes:
                batching.observe(outcome)
                sink(outcome)
        fill()
    return lost
