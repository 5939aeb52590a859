"""Progress for the command line: a bar on a terminal, a line every few seconds elsewhere.

The library never prints. It reports progress through callbacks (the ``progress=`` arguments
of :func:`~rotomorph.simulate.design.simulate_design`, ``paper_report``, ``run_sweep``,
``inverse_file``) and through the ``rotomorph.progress`` logger, whose messages say what it is
doing: a record logged with ``extra={"task": True}`` names a piece of work ("filament 2 of 3
'coil'", "lattice dome on the floor, 20 ghost nodes"), the others what happens within it
("ramp step 3 of 8 at 131.2 °C"). This module, used only by the command-line glue
(:mod:`rotomorph.cli`, :mod:`rotomorph.sweep.command`), shows both:

* on a terminal, one tqdm bar with the count, the elapsed time, the ETA and the latest
  message::

      simulate: 3 of 9 steps |██████▎          | 00:12, ETA 00:20, step 3 at 131.2 °C

* anywhere else (a log file, a notebook, ``| tee``, a batch job), a line on stderr every
  :data:`INTERVAL` seconds (the first after :data:`FIRST_LINE`), and a closing line if any was
  written, so a short command stays silent and a long one is never silent for long::

      rotomorph: simulate: 3 of 9 steps (33 %), 12 s elapsed, ETA 20 s; step 3 at 131.2 °C

With ``--verbose`` every message is also written as its own line (above the bar on a
terminal); with ``--quiet`` nothing is shown.
"""

from __future__ import annotations

import contextlib
import logging
import sys
import threading
import time
from collections.abc import Iterator
from typing import IO, Any

from rotomorph._text import terminal_safe

__all__ = ["FIRST_LINE", "INTERVAL", "ProgressDisplay", "format_duration", "progress_display"]

#: Seconds between two progress lines where there is no terminal.
INTERVAL = 10.0
#: Seconds before the first progress line where there is no terminal (a command that ends
#: sooner writes none).
FIRST_LINE = 5.0
#: Longest message shown next to a bar or in a line (characters).
NOTE_WIDTH = 96

PROGRESS_LOGGER = "rotomorph.progress"


def format_duration(seconds: float) -> str:
    """``"12 s"``, ``"3 min 05 s"``, ``"1 h 02 min"`` (rounded to whole seconds)."""
    s = max(0, round(seconds))
    if s < 60:
        return f"{s} s"
    if s < 3600:
        return f"{s // 60} min {s % 60:02d} s"
    return f"{s // 3600} h {(s % 3600) // 60:02d} min"


def _short(text: str, width: int = NOTE_WIDTH) -> str:
    text = " ".join(text.split())
    return text if len(text) <= width else text[: width - 1] + "…"


class ProgressDisplay:
    """Counts of one piece of work, shown as a bar (terminal) or as periodic lines.

    Parameters
    ----------
    desc
        What is counted, e.g. ``"simulate"``.
    total
        Units of work, or ``None`` while unknown (:meth:`set_total`).
    unit
        Plural noun of a unit (``"steps"``, ``"runs"``); ``""`` with no ``total``: nothing is
        counted, the display shows the time and the note.
    stream
        Where to write (default ``sys.stderr``).
    tty
        Draw a bar (default: whether ``stream`` is a terminal).
    enabled
        ``False`` shows nothing (``--quiet``).
    interval, first
        Seconds between lines and before the first one, without a terminal (default
        :data:`INTERVAL`, :data:`FIRST_LINE`).
    """

    def __init__(
        self,
        desc: str,
        total: int | None = None,
        unit: str = "steps",
        *,
        stream: IO[str] | None = None,
        tty: bool | None = None,
        enabled: bool = True,
        interval: float | None = None,
        first: float | None = None,
    ) -> None:
        self.desc, self.unit = desc, unit
        self.total = total
        self.done = 0
        self.note = ""
        self._task, self._detail = "", ""
        self.initial = 0
        self.enabled = enabled
        self.lines_written = 0
        self._stream: IO[str] = stream if stream is not None else sys.stderr
        isatty = getattr(self._stream, "isatty", None)
        self.tty = bool(isatty()) if tty is None and callable(isatty) else bool(tty)
        self._t0 = time.monotonic()
        self._first_at: float | None = None  # when the first unit (of this session) was done
        self._first_done = 0
        self._lock = threading.RLock()
        self._stop = threading.Event()
        self._bar: Any = None
        self._thread: threading.Thread | None = None
        self._closed = False
        if not enabled:
            return
        if self.tty:
            from tqdm import tqdm

            self._bar = tqdm(
                total=total,
                desc=desc,
                unit=unit,
                file=self._stream,
                leave=True,  # the last state stays on the screen: counts and time taken
                dynamic_ncols=True,
                mininterval=0.2,
                bar_format=self._bar_format(),
            )
        else:
            every = INTERVAL if interval is None else float(interval)
            start = FIRST_LINE if first is None else float(first)
            self._thread = threading.Thread(target=self._lines, args=(every, start), daemon=True)
            self._thread.start()

    # ------------------------------------------------------------------ updates

    def advance(self, n: int = 1) -> None:
        """``n`` more units done."""
        with self._lock:
            if self._first_at is None and n > 0:  # the first of these n is the first unit
                self._first_at, self._first_done = time.monotonic(), self.done + 1
            self.done += int(n)
            if self._bar is not None:
                self._bar.update(int(n))

    def set_done(self, done: int) -> None:
        """Set the units done (counts reported as totals)."""
        with self._lock:
            self.advance(int(done) - self.done)

    def set_total(self, total: int | None) -> None:
        """Change the units of work (when the plan grows or becomes known)."""
        with self._lock:
            self.total = total
            if self._bar is not None:
                self._bar.total = total
                self._bar.bar_format = self._bar_format()
                self._bar.refresh()

    def set_initial(self, done: int) -> None:
        """Units found done before this display started (counted, but not in the ETA's rate:
        a resumed sweep's finished runs)."""
        with self._lock:
            self.initial = int(done)
            if self.done < self.initial:
                self.done = self.initial
                if self._bar is not None:
                    self._bar.n = self.initial
                    self._bar.refresh()

    def set_note(self, text: str) -> None:
        """What is being done now (shown next to the count, after the task)."""
        with self._lock:
            self._detail = text
            self._show_note()

    def set_task(self, text: str) -> None:
        """The piece of work under way (``filament 2 of 3 'coil'``); clears the note."""
        with self._lock:
            self._task, self._detail = text, ""
            self._show_note()

    def _show_note(self) -> None:
        task, detail = " ".join(self._task.split()), " ".join(self._detail.split())
        if task and detail:  # the detail changes, the task is known: shorten the task first
            task = _short(task, max(24, NOTE_WIDTH - 3 - len(detail)))
        self.note = _short(" · ".join(t for t in (task, detail) if t))
        if self._bar is not None:
            self._bar.set_postfix_str(self.note, refresh=False)

    def write(self, text: str) -> None:
        """A line of its own (above the bar on a terminal)."""
        if not self.enabled:
            return
        with self._lock:
            if self._bar is not None:
                self._bar.write(text, file=self._stream)
            else:
                self._stream.write(text + "\n")
                self._stream.flush()

    # ------------------------------------------------------------------ text

    def elapsed(self) -> float:
        """Seconds since the display started."""
        return time.monotonic() - self._t0

    def eta(self) -> float | None:
        """Seconds left at the mean rate of the units after the first (which carries the
        one-time costs: imports, compiling, a worker pool starting); ``None`` before two
        units are done or without a total."""
        if self.total is None or self.done >= self.total or self._first_at is None:
            return None
        rate_units = self.done - self._first_done
        if rate_units <= 0:
            return None
        return (time.monotonic() - self._first_at) * (self.total - self.done) / rate_units

    def status(self) -> str:
        """The line written where there is no terminal (without the ``rotomorph:`` prefix)."""
        with self._lock:
            if self.total is None and not self.unit:  # nothing counted: time and note only
                count = ""
            elif self.total is None:
                count = f"{self.done} {self.unit}, "
            else:
                share = 100.0 * self.done / self.total if self.total else 100.0
                count = f"{self.done} of {self.total} {self.unit} ({share:.0f} %), "
            eta = self.eta()
            timing = f"{format_duration(self.elapsed())} elapsed" + (
                "" if eta is None else f", ETA {format_duration(eta)}"
            )
            note = f"; {self.note}" if self.note else ""
            return f"{self.desc}: {count}{timing}{note}"

    def _bar_format(self) -> str:
        if self.total is None and not self.unit:
            return "{desc}: {elapsed}{postfix}"
        if self.total is None:
            return "{desc}: {n_fmt} {unit}, {elapsed}{postfix}"
        return "{desc}: {n_fmt} of {total_fmt} {unit} |{bar}| {elapsed}, ETA {remaining}{postfix}"

    def _lines(self, interval: float, first: float) -> None:
        wait = first
        while not self._stop.wait(wait):
            self.write(f"rotomorph: {self.status()}")
            self.lines_written += 1
            wait = interval

    # ------------------------------------------------------------------ end

    def close(self) -> None:
        """Stop the display; without a terminal, a closing line if any line was written."""
        if self._closed:
            return
        self._closed = True
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=2.0)
        if self._bar is not None:
            self._bar.refresh()  # the last counts and note, even within mininterval
            self._bar.close()
        elif self.enabled and self.lines_written:
            self.write(f"rotomorph: {self.status()} (finished)")

    def __enter__(self) -> ProgressDisplay:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _MessageHandler(logging.Handler):
    """``rotomorph.progress`` messages -> the display's note (and lines with ``echo``)."""

    def __init__(self, display: ProgressDisplay, echo: bool) -> None:
        super().__init__(logging.INFO)
        self.display, self.echo = display, echo

    def emit(self, record: logging.LogRecord) -> None:
        try:  # what a file contributed (a filament's name) is escaped, never a terminal command
            message = terminal_safe(record.getMessage())
        except Exception:  # a malformed record must not stop the command
            return
        if getattr(record, "task", False):
            self.display.set_task(message)
        else:
            self.display.set_note(message)
        if self.echo:
            self.display.write(f"rotomorph: {message}")


@contextlib.contextmanager
def progress_display(
    desc: str,
    total: int | None = None,
    unit: str = "steps",
    *,
    verbose: bool = False,
    quiet: bool = False,
    stream: IO[str] | None = None,
    tty: bool | None = None,
) -> Iterator[ProgressDisplay]:
    """A :class:`ProgressDisplay` fed with the library's ``rotomorph.progress`` messages while
    the block runs (``verbose``: each also as a line; ``quiet``: nothing shown)."""
    display = ProgressDisplay(desc, total, unit, stream=stream, tty=tty, enabled=not quiet)
    log = logging.getLogger(PROGRESS_LOGGER)
    handler = _MessageHandler(display, echo=verbose and not quiet)
    old = (log.level, log.propagate)
    log.addHandler(handler)
    log.setLevel(logging.INFO)
    log.propagate = False
    try:
        yield display
    finally:
        log.removeHandler(handler)
        log.setLevel(old[0])
        log.propagate = old[1]
        display.close()
