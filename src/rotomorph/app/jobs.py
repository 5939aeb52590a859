"""Background jobs: one worker process per session, a cap on jobs running at once, cancel.

Every browser session gets one :class:`Worker`: a separate process (``spawn`` start method: it
shares no threads, locks or sockets with the web server) that imports the solver and loads its
compiled kernels as soon as the session opens, so a "simulate" starts warm (``prewarm``; a job
submitted during the warm-up stops it and runs at once). A job is a dict sent
to the worker; its events (:mod:`rotomorph.app.worker`) are collected by :meth:`Worker.poll`,
which the page calls a few times a second: the server never waits on a computation, so the
page never blocks.

Cancel ends the worker process (a compiled kernel cannot be interrupted from outside; ending the
process is immediate and leaves nothing half-written: the run folder is the session's own
temporary folder) and starts a fresh one. :class:`Sessions` caps how many jobs run at once over
all sessions (default: the machine's cores) and how many sessions hold a worker; a session idle
for longer than its timeout loses its worker (started again on its next job).
"""

from __future__ import annotations

import multiprocessing as mp
import os
import queue
import re
import shutil
import tempfile
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rotomorph.errors import InvalidParameterError

__all__ = ["BusyError", "Job", "Sessions", "Worker"]


class BusyError(RuntimeError):
    """The session already runs a job, or the server's caps are reached (the message says)."""


#: A session id as the page gets it (``uuid4().hex``); anything else is refused.
_SID = re.compile(r"[0-9a-f]{32}")


@dataclass
class Job:
    """What the page shows of a job: its kind, state and the events received so far.

    ``state`` is ``"running"``, ``"done"``, ``"failed"`` or ``"cancelled"``.
    """

    kind: str
    steps: int = 0
    state: str = "running"
    events: list[dict[str, Any]] = field(default_factory=list)
    topology: dict[str, Any] | None = None
    result: dict[str, Any] | None = None
    error: str = ""
    phase: str = "starting"
    started: float = field(default_factory=time.monotonic)
    first_step_s: float | None = None
    generation: int = 0  # bumped whenever there is something new to draw

    @property
    def running(self) -> bool:
        return self.state == "running"

    def step_events(self) -> list[dict[str, Any]]:
        return [e for e in self.events if e["kind"] == "step"]


class Worker:
    """A session's worker process and its current job.

    Parameters
    ----------
    prewarm
        Each process heats the warm-up designs before its first job
        (:func:`rotomorph.app.worker.run_worker`); ``False`` starts it cold.
    """

    def __init__(self, *, prewarm: bool = True) -> None:
        self._ctx = mp.get_context("spawn")
        self._process: Any = None
        self.prewarm = prewarm
        self.ready = False
        self.warmed: list[str] = []  # the warm-up stages the current process heated
        self.job: Job | None = None
        self.folder = Path(tempfile.mkdtemp(prefix="rotomorph-app-"))
        self._runs = 0
        self.start()

    def start(self) -> None:
        from rotomorph.app.worker import run_worker

        self._inbox = self._ctx.Queue()
        self._outbox = self._ctx.Queue()
        self._process = self._ctx.Process(
            target=run_worker, args=(self._inbox, self._outbox, self.prewarm), daemon=True
        )
        self._process.start()
        self.ready = False
        self.warmed = []

    @property
    def alive(self) -> bool:
        return self._process is not None and self._process.is_alive()

    def submit(self, job: Job, payload: dict[str, Any]) -> None:
        """Start ``job`` (the worker must be idle)."""
        if not self.alive:
            self.start()
        self._runs += 1  # each job writes into a folder of its own
        payload = {**payload, "folder": str(self.folder / f"{job.kind}{self._runs}")}
        self.job = job
        self._inbox.put(payload)

    def poll(self) -> Job | None:
        """Collect the events that arrived; return the current job (None if none)."""
        while True:
            try:
                event = self._outbox.get_nowait()
            except queue.Empty:
                break
            except (EOFError, OSError):  # pragma: no cover - a worker killed mid-put
                break
            self._receive(event)
        job = self.job
        if job is not None and job.running and not self.alive:
            job.state, job.error = "failed", "the worker process ended unexpectedly"
            job.generation += 1
        return job

    def _receive(self, event: dict[str, Any]) -> None:
        kind = event["kind"]
        if kind == "ready":
            self.ready = True
            self.warmed = list(event["warmed"])
            return
        job = self.job
        if job is None or not job.running:
            return
        if kind == "phase":
            job.phase = str(event["text"])
        elif kind == "topology":
            job.topology = event
        elif kind == "step":
            job.events.append(event)
            if job.first_step_s is None and event["step"] >= 1:
                job.first_step_s = time.monotonic() - job.started
            job.generation += 1
        elif kind == "iteration":
            job.events.append(event)
            job.phase = f"iteration {event['iteration']}: objective {event['objective']:.4g}"
            job.generation += 1
        elif kind == "done":
            job.state, job.result = "done", event
            job.generation += 1
        elif kind == "error":
            job.state, job.error = "failed", str(event["message"])
            job.generation += 1

    def cancel(self) -> None:
        """End the running job now: the process ends and a fresh one starts warming up."""
        if self.job is not None and self.job.running:
            self.job.state = "cancelled"
            self.job.generation += 1
        self.stop()
        self.start()

    def stop(self) -> None:
        """End the worker process."""
        if self._process is not None and self._process.is_alive():
            self._process.terminate()
            self._process.join(timeout=5)
            if self._process.is_alive():  # pragma: no cover - ignored SIGTERM
                self._process.kill()
                self._process.join(timeout=5)
        self._process = None
        self.ready = False

    def close(self) -> None:
        """End the process and remove the session's files."""
        self.stop()
        shutil.rmtree(self.folder, ignore_errors=True)


@dataclass
class _Session:
    worker: Worker | None = None
    seen: float = field(default_factory=time.monotonic)
    files: dict[str, Any] = field(default_factory=dict)


class Sessions:
    """Sessions by id: each with at most one worker; caps on running jobs and on workers.

    Parameters
    ----------
    max_jobs
        Jobs running at once over all sessions (default: the number of CPU cores).
    max_workers
        Sessions holding a worker process at once; the least recently seen idle one gives
        its worker up when a new session needs one.
    idle_timeout
        Seconds after which a session that was not seen loses its worker and files.
    prewarm
        Workers warm up before their first job (:class:`Worker`); ``False`` where the first
        step's latency does not matter (it then includes loading the kernels).
    """

    def __init__(
        self,
        *,
        max_jobs: int | None = None,
        max_workers: int = 8,
        idle_timeout: float = 3600.0,
        prewarm: bool = True,
    ) -> None:
        self.prewarm = prewarm
        self.max_jobs = max(1, max_jobs or os.cpu_count() or 1)
        self.max_workers = max(1, max_workers)
        self.idle_timeout = idle_timeout
        self._sessions: dict[str, _Session] = {}
        self._lock = threading.RLock()

    def _get(self, sid: str) -> _Session:
        if not (isinstance(sid, str) and _SID.fullmatch(sid)):
            raise InvalidParameterError(
                "session", "is not a session of this server; reload the page"
            )
        with self._lock:
            self._reap()
            session = self._sessions.setdefault(sid, _Session())
            session.seen = time.monotonic()
            return session

    def files(self, sid: str) -> dict[str, Any]:
        """Per-session store of server-side values (uploaded machine profile, …)."""
        return self._get(sid).files

    def worker(self, sid: str) -> Worker:
        """The session's worker, started if it has none."""
        with self._lock:
            session = self._get(sid)
            if session.worker is None:
                holders = [s for s in self._sessions.values() if s.worker is not None]
                if len(holders) >= self.max_workers:
                    idle = [
                        s
                        for s in holders
                        if not (s.worker and s.worker.job and s.worker.job.running)
                    ]
                    if not idle:
                        raise BusyError(
                            f"{self.max_workers} sessions are computing; try again when one ends"
                        )
                    oldest = min(idle, key=lambda s: s.seen)
                    assert oldest.worker is not None
                    oldest.worker.close()
                    oldest.worker = None
                session.worker = Worker(prewarm=self.prewarm)
            return session.worker

    def job(self, sid: str) -> Job | None:
        """The session's current job with its new events (None if it never ran one)."""
        with self._lock:
            session = self._get(sid)
            return None if session.worker is None else session.worker.poll()

    def running(self) -> int:
        """Jobs running over all sessions."""
        with self._lock:
            return sum(
                1
                for s in self._sessions.values()
                if s.worker is not None
                and s.worker.job is not None
                and s.worker.poll() is not None
                and s.worker.job.running
            )

    def submit(self, sid: str, job: Job, payload: dict[str, Any]) -> None:
        """Start ``job`` in the session's worker.

        Raises
        ------
        BusyError
            The session already runs a job, or the cap on running jobs is reached (the
            message says so).
        """
        with self._lock:
            worker = self.worker(sid)
            current = worker.poll()
            if current is not None and current.running:
                raise BusyError("a job is running in this session; cancel it or wait")
            if self.running() >= self.max_jobs:
                raise BusyError(
                    f"{self.max_jobs} job(s) are running (the limit of this server); "
                    "try again when one ends"
                )
            worker.submit(job, payload)

    def cancel(self, sid: str) -> None:
        with self._lock:
            session = self._get(sid)
            if session.worker is not None:
                session.worker.cancel()

    def _reap(self) -> None:
        now = time.monotonic()
        for sid, session in list(self._sessions.items()):
            if now - session.seen > self.idle_timeout:
                if session.worker is not None:
                    session.worker.close()
                del self._sessions[sid]

    def close(self) -> None:
        """End every worker (the server is stopping)."""
        with self._lock:
            for session in self._sessions.values():
                if session.worker is not None:
                    session.worker.close()
            self._sessions.clear()
