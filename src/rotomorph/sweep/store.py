"""The run store of a sweep folder: one record per finished run, written atomically.

Layout of a sweep folder ``DIR``::

    DIR/sweep.json               the validated sweep (with its base design) of the last start
    DIR/runs/<id[:2]>/<id>.json  one record per finished run (the completion marker)
    DIR/runs/<id[:2]>/<id>.h5    the run's full results (only with ``hdf5 = true``)
    DIR/results.parquet          the table (:mod:`rotomorph.sweep.table`)
    DIR/.lock                    locked (``lockf``) while a sweep writes to DIR

A run is *finished* exactly when its ``.json`` record exists and can be trusted
(:func:`rotomorph.sweep.records.check_record`: schema, run id, checksum, and the sha256 of its
HDF5 file). Records are written to a temporary file and renamed
(:func:`rotomorph.io.atomic.atomic_write_text`), after the run's HDF5 file, so a killed sweep
leaves either a complete run or none; finished runs are never recomputed. A record that cannot
be trusted (truncated, empty, binary, copied under another run's id, edited) is reported in one
warning line naming the file, and its run is computed again. The lock is released by the
operating system when the process dies (even by SIGKILL), so a restart never finds a stale
lock; two sweeps writing to one folder at the same time are refused. Temporary files of a
killed writer are hidden (dot-files, never counted as records) and deleted by the next lock
holder.
"""

from __future__ import annotations

import json
import logging
import os
from collections.abc import Iterable, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.results import RunResults, write_results
from rotomorph.sweep.records import DamagedRecord, check_record, file_sha256, seal_record

__all__ = ["RunStore"]

logger = logging.getLogger(__name__)


class RunStore:
    """Finished runs of a sweep folder (created if missing).

    Parameters
    ----------
    folder
        The sweep's output folder.
    fsync
        Flush every record to disk before renaming it (default; survives power loss).
    """

    def __init__(self, folder: str | os.PathLike[str], *, fsync: bool = True) -> None:
        self.folder = Path(folder)
        if self.folder.exists() and not self.folder.is_dir():
            raise InvalidParameterError("output", f"{self.folder}: exists and is not a folder")
        (self.folder / "runs").mkdir(parents=True, exist_ok=True)
        self.fsync = fsync
        self._lock: IO[str] | None = None

    # -- locking ---------------------------------------------------------------------------

    def lock(self) -> None:
        """Take the folder's lock or raise :class:`InvalidParameterError` if another holds it."""
        import fcntl

        fh = open(self.folder / ".lock", "a+")
        try:  # a POSIX record lock: held by this process only, never by forked children
            fcntl.lockf(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            fh.close()
            raise InvalidParameterError(
                "output", f"{self.folder}: another sweep is writing to this folder; wait for it"
            ) from None
        self._lock = fh
        self._remove_stale()

    def _remove_stale(self) -> None:
        """Delete temporary files a killed writer left behind (only the lock holder writes)."""
        for tmp in (self.folder / "runs").glob("*/.*.tmp-*"):
            tmp.unlink(missing_ok=True)

    def unlock(self) -> None:
        """Release the lock (no-op if not held)."""
        if self._lock is not None:
            self._lock.close()
            self._lock = None

    def __enter__(self) -> RunStore:
        self.lock()
        return self

    def __exit__(self, *exc: object) -> None:
        self.unlock()

    # -- records ---------------------------------------------------------------------------

    def record_path(self, run_id: str) -> Path:
        """Where the record of ``run_id`` lives."""
        return self.folder / "runs" / run_id[:2] / f"{run_id}.json"

    def results_path(self, run_id: str) -> Path:
        """Where the HDF5 results of ``run_id`` live (when written)."""
        return self.record_path(run_id).with_suffix(".h5")

    def stored(self) -> set[str]:
        """Ids of every run with a record file in the folder (trusted or not)."""
        runs = self.folder / "runs"
        return {p.stem for p in runs.glob("*/*.json") if not p.name.startswith(".")}

    def finished(self, ids: Iterable[str] | None = None) -> dict[str, dict[str, Any]]:
        """Trusted records by run id: of every stored run, or of those of ``ids`` stored.

        A record that cannot be trusted is left out (its run counts as not finished) with one
        warning naming its file and the reason.
        """
        stored = self.stored()
        wanted = stored if ids is None else stored & set(ids)
        out = {}
        for run_id in sorted(wanted):
            path = self.record_path(run_id)
            try:
                out[run_id] = check_record(path, run_id)
            except (DamagedRecord, OSError) as err:
                reason = err.strerror if isinstance(err, OSError) else str(err)
                logger.warning(
                    "sweep record %s %s: ignored, the run is computed again",
                    path.relative_to(self.folder),
                    reason,
                )
        return out

    def read(self, run_id: str) -> dict[str, Any]:
        """The trusted record of a finished run.

        Raises
        ------
        InvalidParameterError
            The record is missing or cannot be trusted (naming the file and why).
        """
        path = self.record_path(run_id)
        try:
            return check_record(path, run_id)
        except (DamagedRecord, OSError) as err:
            reason = err.strerror if isinstance(err, OSError) else str(err)
            raise InvalidParameterError(str(path), str(reason)) from None

    def records(self, ids: Iterable[str] | None = None) -> Iterator[dict[str, Any]]:
        """Trusted records of the finished runs (all, or those in ``ids``), by id."""
        yield from self.finished(ids).values()

    def write(self, record: Mapping[str, Any], results: RunResults | None = None) -> Path:
        """Store a finished run: its HDF5 results (if any) first, then its record (sealed with
        its checksum and the HDF5 file's sha256, :func:`~rotomorph.sweep.records.seal_record`)."""
        run_id = str(record["run_id"])
        path = self.record_path(run_id)
        path.parent.mkdir(exist_ok=True)
        digest = None
        if results is not None:
            write_results(
                self.results_path(run_id),
                design=results.design,
                edges=results.edges,
                branch=results.branch,
                positions=results.positions,
                scalars=results.scalars,
                fields=results.fields,
                units=results.units,
                metadata={**results.metadata, "run_id": run_id},
                static=results.static,
                programs=results.programs,
            )
            digest = file_sha256(self.results_path(run_id))
        text = json.dumps(seal_record(record, digest), sort_keys=True, allow_nan=False)
        return atomic_write_text(path, text + "\n", fsync=self.fsync)
