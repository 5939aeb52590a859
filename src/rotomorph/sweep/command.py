"""The ``rotomorph sweep`` command: parser arguments and the command (logic lives here).

``rotomorph sweep SWEEP.toml -o DIR [--scheduler tcp://HOST:PORT | --workers N] [--plot]``
runs (or resumes) the sweep into ``DIR`` with its progress (runs done of the total, ok / failed /
to go, elapsed time and ETA: a bar on a terminal, a line every 10 s elsewhere) and prints a
one-line summary. ``rotomorph sweep --schema`` prints the sweep file's JSON
Schema. Running the same command again after an interruption computes only the missing runs.
Exit code 1 when runs were lost to a crashed worker (run again to finish them).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from rotomorph._text import terminal_safe
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import check_writable

__all__ = ["add_arguments", "check_scheduler_address", "command"]


def add_arguments(p: argparse.ArgumentParser) -> None:
    """Arguments of ``rotomorph sweep``."""
    p.add_argument("sweep", nargs="?", metavar="SWEEP.toml")
    p.add_argument("-o", "--output", metavar="DIR", help="sweep folder (created; resumable)")
    p.add_argument("--scheduler", metavar="tcp://HOST:PORT", help="run on a Dask scheduler")
    p.add_argument("--workers", type=int, help="local worker processes (default: CPU count)")
    p.add_argument("--plot", action="store_true", help="draw the sweep's figures in DIR/figures")
    p.add_argument("--schema", action="store_true", help="print the sweep file's JSON Schema")


def check_scheduler_address(address: str) -> None:
    """Refuse a ``--scheduler`` that is not a Dask scheduler address (before any folder exists).

    Raises
    ------
    InvalidParameterError
        A missing port, an unknown scheme (e.g. the dashboard's ``http://HOST:8787``), or no
        dask.distributed installed; naming ``--scheduler`` and the expected form.
    """
    form = "write tcp://HOST:PORT (the scheduler's port, 8786 by default; not the dashboard's)"
    try:
        from distributed.comm.addressing import parse_address, parse_host_port
        from distributed.comm.registry import get_backend
    except ImportError:  # pragma: no cover - optional dependency
        raise InvalidParameterError(
            "--scheduler", "needs dask.distributed: pip install 'rotomorph[sweep]'"
        ) from None
    try:
        scheme, location = parse_address(address)
        get_backend(scheme)
        if scheme in ("tcp", "tls"):
            parse_host_port(location)
    except (ValueError, TypeError) as err:
        raise InvalidParameterError(
            "--scheduler", f"{address!r} is not a Dask scheduler address ({err}); {form}"
        ) from None


def _show(display: Any) -> Any:
    """A ``run_sweep`` progress callback feeding a :class:`rotomorph._progress.ProgressDisplay`
    (runs found finished count as done, not toward the ETA's rate)."""

    def progress(p: Any) -> None:
        if display.total != p.total:
            display.set_total(p.total)
            display.set_initial(p.skipped)
        found = f", {p.skipped} found finished" if p.skipped else ""
        display.set_note(f"{p.ok} ok, {p.failed} failed, {p.remaining} to go{found}")
        display.set_done(p.done)

    return progress


def command(args: argparse.Namespace) -> int:
    """Run a parameter study from SWEEP.toml into DIR (resumable: the same command finishes an
    interrupted sweep), on local processes or a Dask scheduler."""
    from rotomorph.sweep.spec import load_sweep, sweep_schema

    if args.schema:
        sys.stdout.write(json.dumps(sweep_schema(), indent=2) + "\n")
        if args.sweep is None:
            return 0
    if args.sweep is None:
        raise InvalidParameterError("SWEEP", "give SWEEP.toml (or --schema)")
    if not args.output:
        raise InvalidParameterError("-o/--output", "give the sweep folder")
    path = Path(args.sweep)
    if not path.is_file():
        raise InvalidParameterError("SWEEP", f"{args.sweep}: no such file")
    if args.scheduler is not None and args.workers is not None:
        raise InvalidParameterError("--workers", "is for the local pool; drop it with --scheduler")
    if args.scheduler is not None:
        check_scheduler_address(args.scheduler)
    out = Path(args.output)
    if out.exists() and not out.is_dir():
        raise InvalidParameterError("-o/--output", f"{args.output}: exists and is not a folder")
    check_writable(out, "-o/--output", create_parent=False)
    sweep = load_sweep(path)
    from rotomorph._progress import progress_display
    from rotomorph.sweep.runner import run_sweep

    verbose, quiet = getattr(args, "verbose", False), getattr(args, "quiet", False)
    with progress_display("sweep", None, "runs", verbose=verbose, quiet=quiet) as shown:
        result = run_sweep(
            sweep, out, scheduler=args.scheduler, workers=args.workers, progress=_show(shown)
        )
    statuses = result.table.column("status").to_pylist()
    counts = {s: statuses.count(s) for s in ("ok", "invalid", "failed")}
    p = result.progress
    sys.stdout.write(
        f"wrote {result.table_path}: {len(statuses)} point(s), {p.total} run(s) "
        f"({counts['ok']} ok, {counts['invalid']} invalid, {counts['failed']} failed); "
        f"{p.ok + p.failed} computed now, {p.skipped} found finished, "
        f"{result.wall_time:.1f} s\n"
    )
    if args.plot:
        from rotomorph.sweep.figures import plot_sweep

        try:
            figs = plot_sweep(
                result.table, [q.column for q in sweep.parameters], sweep.outputs, out / "figures"
            )
        except Exception as err:  # drawing must never cost the computed sweep (table written)
            sys.stderr.write(
                f"rotomorph: warning: figures not drawn ({type(err).__name__}: "
                f"{terminal_safe(' '.join(str(err).split())[:300])}); the table is kept\n"
            )
        else:
            sys.stdout.write(f"wrote {len(figs)} figure(s) to {out / 'figures'}\n")
    if result.lost:
        sys.stderr.write(
            f"rotomorph: error: {len(result.lost)} run(s) lost to a failed worker "
            f"(first: {terminal_safe(result.lost[0])}); run the same command again to finish "
            "them\n"
        )
        return 1
    return 0
