"""Executors of a sweep: the local process pool, a Dask scheduler, or the caller's own.

The local pool's workers start from a ``forkserver`` that has already imported rotomorph and
loaded its kernels, and they die with the process that owns the pool: each looks at its owner
every :data:`OWNER_POLL_S` seconds and exits when the owner is gone, a zombie (killed, not yet
reaped by its parent) or a reused pid (``/proc/<pid>/stat``: state and start time). A worker
that only asked ``os.kill(pid, 0)`` would outlive a SIGKILLed owner whose parent has not reaped
it yet, keeping the owner's stdout and stderr open, so a program reading them would wait for
ever.

A ``--scheduler`` address is first asked who it is (:func:`probe_scheduler`: a Dask
``identity`` exchange, :data:`HANDSHAKE_TIMEOUT_S` seconds at most), so a port that is not a
Dask scheduler (a web server, a dashboard, a worker) fails in seconds with one line, instead of
the client waiting forever for a reply that never comes.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import threading
import time
from collections.abc import Iterator
from typing import Any, Final

from rotomorph.errors import InvalidParameterError

__all__ = [
    "CONNECT_TIMEOUT_S",
    "HANDSHAKE_TIMEOUT_S",
    "OWNER_POLL_S",
    "local_executor",
    "open_executor",
    "owner_alive",
    "probe_scheduler",
]

#: Seconds a scheduler address has to answer the identity handshake.
HANDSHAKE_TIMEOUT_S: Final = 10.0
#: Seconds the Dask client may take to connect after a successful handshake.
CONNECT_TIMEOUT_S: Final = 20.0


def probe_scheduler(address: str, timeout: float | None = None) -> None:
    """Raise unless a Dask scheduler answers at ``address`` within ``timeout`` seconds
    (default :data:`HANDSHAKE_TIMEOUT_S`).

    Connects with Dask's own comm layer, sends ``{"op": "identity"}`` and expects the
    scheduler's identity back (``{"type": "Scheduler", ...}``); every step has the deadline.

    Raises
    ------
    InvalidParameterError
        Naming ``--scheduler``: nothing listens, the peer is not Dask (no reply in time, or
        garbage), or it is a Dask worker or nanny rather than the scheduler.
    """
    import asyncio
    import socket

    from distributed.comm import connect
    from distributed.comm.addressing import parse_address, parse_host_port

    timeout = HANDSHAKE_TIMEOUT_S if timeout is None else timeout
    form = "give the scheduler's tcp://HOST:PORT (8786 by default, not the dashboard's 8787)"
    scheme, location = parse_address(address)
    if scheme in ("tcp", "tls"):  # nothing listening: say so at once, not after the timeout
        host, port = parse_host_port(location)
        try:
            socket.create_connection((host, port), timeout=timeout).close()
        except TimeoutError:
            raise InvalidParameterError(
                "--scheduler", f"{address}: no answer within {timeout:g} s (host down?); {form}"
            ) from None
        except OSError as err:
            raise InvalidParameterError(
                "--scheduler",
                f"{address}: nothing listens there ({err.strerror or err}); is the scheduler "
                f"running? {form}",
            ) from None

    async def identity() -> Any:
        comm = await asyncio.wait_for(connect(address, timeout=timeout), timeout)
        try:
            await asyncio.wait_for(comm.write({"op": "identity", "reply": True}), timeout)
            return await asyncio.wait_for(comm.read(), timeout)
        finally:
            comm.abort()

    result: dict[str, Any] = {}

    def run() -> None:  # its own event loop, also when the caller runs one (a notebook)
        try:
            result["reply"] = asyncio.run(identity())
        except BaseException as exc:  # reported below, in the caller's thread
            result["error"] = exc

    thread = threading.Thread(target=run, name="rotomorph-scheduler-probe", daemon=True)
    thread.start()
    thread.join(3 * timeout + 5)
    failure = result.get("error")
    if thread.is_alive() or isinstance(failure, asyncio.TimeoutError | TimeoutError):
        raise InvalidParameterError(
            "--scheduler",
            f"{address}: no Dask scheduler answered within {timeout:g} s (is this port a "
            f"web server or another service?); {form}",
        )
    if failure is not None:
        why = " ".join(str(failure).split()) or type(failure).__name__
        raise InvalidParameterError(
            "--scheduler", f"cannot reach a Dask scheduler at {address}: {why}; {form}"
        )
    reply = result.get("reply")
    kind = reply.get("type") if isinstance(reply, dict) else None
    if kind != "Scheduler":
        what = f"a Dask {kind}" if isinstance(kind, str) else "not a Dask scheduler"
        raise InvalidParameterError(
            "--scheduler", f"{address}: answers as {what!s:.60}, not a scheduler; {form}"
        )


@contextlib.contextmanager
def open_executor(
    executor: Any, scheduler: str | None, workers: int | None
) -> Iterator[cf.Executor]:
    """The executor a sweep runs on: ``executor`` (its ``get_executor()`` if it has one; the
    caller keeps it), else a Dask client connected to ``scheduler`` (call
    :func:`probe_scheduler` first), else a :func:`local_executor` of ``workers`` processes (stopped
    at once on an error or Ctrl-C)."""
    if executor is not None and scheduler is not None:
        raise InvalidParameterError("scheduler", "give an executor or a scheduler, not both")
    if executor is not None:
        yield executor.get_executor() if hasattr(executor, "get_executor") else executor
        return
    if scheduler is not None:
        try:
            from distributed import Client
        except ImportError:  # pragma: no cover - optional dependency
            raise InvalidParameterError(
                "scheduler", "needs dask.distributed: pip install 'rotomorph[sweep]'"
            ) from None
        try:
            client = Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S:g}s")
        except (OSError, ValueError) as err:  # unreachable, or not an address (no port)
            raise InvalidParameterError(
                "scheduler", f"cannot reach the Dask scheduler at {scheduler}: {err}"
            ) from None
        with client:
            yield client.get_executor()
        return
    pool = local_executor(workers)
    try:
        yield pool
    except BaseException:  # Ctrl-C or an error: drop queued runs, stop the running ones
        _terminate(pool)
        raise
    pool.shutdown(wait=True)


def local_executor(workers: int | None = None) -> cf.ProcessPoolExecutor:
    """The default local pool: ``workers`` processes (default: CPU count), warmed up.

    Use it as a context manager to share one pool between several sweeps
    (``run_sweep(..., executor=pool)``).
    """
    if workers is not None and workers < 1:
        raise InvalidParameterError("workers", f"must be >= 1; got {workers}")
    return cf.ProcessPoolExecutor(
        max_workers=workers or os.cpu_count() or 1,
        mp_context=_pool_context(),
        initializer=_warm_worker,
        initargs=(os.getpid(),),
    )


def _pool_context() -> Any:
    """``forkserver`` (POSIX) or ``spawn``: workers start as clean processes that inherit no
    locks, signal handlers or threads of the caller; the server has imported rotomorph and
    loaded the solver's kernels once, so every worker it forks starts warm."""
    import multiprocessing

    if "forkserver" not in multiprocessing.get_all_start_methods():  # pragma: no cover
        return multiprocessing.get_context("spawn")
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(["rotomorph.sweep._warm"])  # kernels loaded once, forked warm
    return ctx


def _proc_stat(pid: int) -> tuple[str, str] | None:
    """``(state, start time)`` of ``pid`` from ``/proc/<pid>/stat`` (Linux): the state letter
    (``"Z"`` zombie, ``"X"`` dead, …) and the start time in clock ticks since boot, which tells
    a reused pid from the original; ``None`` when the process is gone."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            stat = fh.read()
    except (FileNotFoundError, ProcessLookupError):
        return None
    rest = stat[stat.rindex(b")") + 2 :].split()  # the command name may hold spaces and ")"
    return rest[0].decode(), rest[19].decode()


def owner_alive(owner: int, start: str | None) -> bool:
    """Whether process ``owner`` (started at ``start``, see :func:`_proc_stat`) still runs.

    On Linux a zombie (killed, not yet reaped by its parent) or a reused pid counts as gone:
    ``os.kill(pid, 0)`` alone succeeds on a zombie, so workers would outlive a SIGKILLed owner
    and hold its pipes open. Without ``/proc`` the signal check is all there is.
    """
    if _HAS_PROC:
        stat = _proc_stat(owner)
        return stat is not None and stat[0] not in ("Z", "X") and stat[1] == start
    try:
        os.kill(owner, 0)
    except (ProcessLookupError, PermissionError):  # gone, or the pid reused by another user
        return False
    return True


_HAS_PROC = os.path.exists("/proc/self/stat")
#: Seconds between two looks at the owner from a worker.
OWNER_POLL_S = 0.25


def _warm_worker(owner: int) -> None:
    """Pool initializer: Ctrl-C is the owner's to handle (it stops the pool), SIGTERM ends
    the worker, the worker exits within :data:`OWNER_POLL_S` when the owner process (pid
    ``owner``) is gone — killed by SIGKILL, and even while it is an unreaped zombie
    (:func:`owner_alive`); then the solver's kernels are loaded before the first run (see
    ``_warm``)."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    stat = _proc_stat(owner) if _HAS_PROC else None
    start = stat[1] if stat is not None else None
    if _HAS_PROC and (stat is None or stat[0] in ("Z", "X")):
        os._exit(1)  # the owner died before this worker started

    def watch() -> None:
        while True:
            time.sleep(OWNER_POLL_S)
            if not owner_alive(owner, start):
                os._exit(1)

    threading.Thread(target=watch, name="rotomorph-owner-watch", daemon=True).start()
    import rotomorph.sweep._warm  # noqa: F401


def _terminate(pool: cf.ProcessPoolExecutor) -> None:
    """Cancel queued runs and stop the workers now (their runs are not stored: a restart
    computes them)."""
    terminate = getattr(pool, "terminate_workers", None)  # Python >= 3.14
    if terminate is not None:
        terminate()
        return
    workers = list((getattr(pool, "_processes", None) or {}).values())  # before shutdown
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in workers:
        proc.terminate()
