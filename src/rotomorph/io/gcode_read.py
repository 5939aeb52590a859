"""Strict reader for the G-code that :mod:`rotomorph.io.gcode` writes.

It rebuilds, per filament, the points, speed, nozzle angle, pressure set-points and the
metadata comment, and raises :class:`~rotomorph.errors.GcodeParseError` (with the line number)
on anything it does not expect: unknown words or commands, a print move with both pressures
off, a travel move with a pressure on, a filament without its metadata comment, a
``setAlicatPress`` in an rs274 file, and so on. It is a checker for our own files, not a
general G-code interpreter.
"""

from __future__ import annotations

import re
import string
from dataclasses import dataclass
from pathlib import Path as FilePath

import numpy as np

from rotomorph.design.program import PrintProgram
from rotomorph.errors import GcodeParseError, InvalidParameterError
from rotomorph.io.machine import MachineProfile

__all__ = ["ReadFilament", "parse_gcode", "read_gcode"]

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)"
_META = re.compile(
    r"; filament (\d+) layer=(\d+) radius=(\S+) active_fraction=(\S+) "
    r"active_material=(\S+) passive_material=(\S+)$"
)


@dataclass(frozen=True)
class ReadFilament:
    """One filament read back from G-code.

    Attributes
    ----------
    program
        The rebuilt :class:`PrintProgram` (the last vertex speed repeats the last move's).
    pressure
        (active, passive) set-points (psi) while printing it.
    line
        Line number (1-based) of its first print move.
    """

    program: PrintProgram
    pressure: tuple[float, float]
    line: int


def _template_regex(template: str) -> re.Pattern[str]:
    parts = []
    for literal, name, _spec, _conv in string.Formatter().parse(template):
        parts.append(re.escape(literal))
        if name == "port":
            parts.append(r"(?P<port>\d+)")
        elif name == "psi":
            parts.append(rf"(?P<psi>{_NUM})")
    return re.compile("".join(parts) + "$")


def parse_gcode(text: str, machine: MachineProfile) -> list[ReadFilament]:
    """Filaments of a G-code ``text`` written for ``machine`` (see module docstring).

    Raises
    ------
    GcodeParseError
        On the first unexpected line, with its number.
    """
    m = machine
    axes = {m.x_axis: 0, m.y_axis: 1, m.z_axis: 2, m.rotary_axis: 3}
    if m.dialect == "aerotech":
        press_re = re.compile(rf"Call setAlicatPress P(?P<port>\d+) Q(?P<psi>{_NUM})$")
        setup = {"G71", "G76", "G90"}
    else:
        press_re = _template_regex(m.pressure_template)
        setup = {"G21", "G90"}
    dwell_re = re.compile(rf"G4 {'S' if m.dialect == 'marlin' else 'P'}{_NUM}$")
    extra = {t for t in (m.uv_on_template, m.uv_off_template) if t}
    word_re = re.compile(rf"([A-Z])({_NUM})$")
    pos = np.full(4, np.nan)
    pressure = {m.active_port: 0.0, m.passive_port: 0.0}
    meta: re.Match[str] | None = None
    current: dict | None = None
    out: list[ReadFilament] = []

    def fail(no: int, why: str, line: str) -> GcodeParseError:
        return GcodeParseError(f"line {no}: {why}: {line!r}")

    def close(no: int, line: str) -> None:
        nonlocal current, meta
        if current is None:
            return
        if len(current["points"]) < 2:
            raise fail(no, "filament has no print move", line)
        _, layer, radius, frac, act, pas = meta.groups()  # type: ignore[union-attr]
        speed = current["speed"] + [current["speed"][-1]]
        try:
            prog = PrintProgram(
                np.array(current["points"]),
                np.array(speed) / m.feed_scale,
                np.array(current["angle"]) / m.rotary_scale,
                float(radius),
                float(frac),
                act,
                pas,
                int(layer),
            )
        except InvalidParameterError as exc:
            raise fail(no, f"filament is not a valid PrintProgram ({exc})", line) from exc
        out.append(ReadFilament(prog, current["pressure"], current["line"]))
        current, meta = None, None

    seen_setup: set[str] = set()
    for no, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith(";"):
            mm = _META.match(line)
            if mm:
                if current is not None or meta is not None:
                    raise fail(no, "filament comment inside another filament", line)
                meta = mm
            continue
        if line in setup:
            seen_setup.add(line)
            continue
        if seen_setup != setup:
            raise fail(no, f"motion before the setup block {sorted(setup)}", line)
        pm = press_re.match(line)
        if pm:
            port, psi = int(pm["port"]), float(pm["psi"])
            if port not in pressure:
                raise fail(no, f"unknown pressure port {port}", line)
            if not (m.min_pressure <= psi <= m.max_pressure):
                raise fail(no, f"pressure {psi} psi outside the machine limits", line)
            pressure[port] = psi
            if all(v == 0 for v in pressure.values()):
                close(no, line)
            continue
        if line in extra or dwell_re.match(line) or (line == "M2" and m.dialect != "marlin"):
            if any(pressure.values()):
                raise fail(no, "dwell or UV line with a pressure on", line)
            continue
        words = line.split()
        if words[0] not in ("G0", "G1"):
            raise fail(no, "unexpected command", line)
        new = pos.copy()
        feed = None
        for w in words[1:]:
            wm = word_re.match(w)
            if not wm:
                raise fail(no, f"malformed word {w!r}", line)
            letter, value = wm[1], float(wm[2])
            if letter in axes:
                new[axes[letter]] = value
            elif letter == "F" and words[0] == "G1":
                feed = value
            else:
                raise fail(no, f"unexpected word {w!r}", line)
        printing = any(pressure.values())
        if words[0] == "G0":
            if printing:
                raise fail(no, "travel move (G0) with a pressure on", line)
            pos = new
            continue
        if not printing:
            raise fail(no, "print move (G1) with both pressures off", line)
        if feed is None or feed <= 0:
            raise fail(no, "print move without a positive F", line)
        if np.isnan(new).any():
            raise fail(no, "print move from an unknown position", line)
        if current is None:
            if meta is None:
                raise fail(no, "print move without a '; filament ...' comment", line)
            current = {
                "points": [pos[:3].copy()],
                "angle": [pos[3]],
                "speed": [],
                "line": no,
                "pressure": (pressure[m.active_port], pressure[m.passive_port]),
            }
        elif current["pressure"] != (pressure[m.active_port], pressure[m.passive_port]):
            raise fail(no, "pressure changed in the middle of a filament", line)
        current["points"].append(new[:3].copy())
        current["angle"].append(new[3])
        current["speed"].append(feed)
        pos = new
    if current is not None or any(pressure.values()):
        raise fail(len(text.splitlines()), "file ends with a pressure on", "<end of file>")
    return out


def read_gcode(path: str | FilePath, machine: MachineProfile) -> list[ReadFilament]:
    """Read a G-code file written for ``machine``; see :func:`parse_gcode`."""
    return parse_gcode(FilePath(path).read_text(encoding="utf-8"), machine)
