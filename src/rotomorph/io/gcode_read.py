"""Strict reader and checker of G-code programs against a machine profile.

:func:`check_gcode` reads a program line by line as the profile's controller would and refuses
anything it does not expect (:class:`~rotomorph.errors.GcodeParseError`, with the line number):
an unknown command or word, a missing setup block, header or footer, a print move with every
channel off, a travel with a channel on, a pressure change inside a filament, a rotary word on a
rapid ``G0`` (its rate is not controlled), a rotary-only move, a ``G1`` without a feed where the
dialect needs one. It then checks every move against the profile and raises
:class:`~rotomorph.errors.MachineLimitError` naming the profile key: envelope (travel included),
feed range, rotation rate of every move with a rotary word (travel included), pressure range,
and the rotary word within one turn at every filament start. :func:`parse_gcode` also rebuilds
each filament's :class:`~rotomorph.design.program.PrintProgram` from the ``; filament …``
comment that rotomorph writes.
"""

from __future__ import annotations

import math
import re
import string
from dataclasses import dataclass, field
from pathlib import Path as FilePath
from typing import Any

import numpy as np

from rotomorph.design.program import PrintProgram
from rotomorph.errors import GcodeParseError, InvalidParameterError, MachineLimitError
from rotomorph.io import gcode_aerotech
from rotomorph.io.machine import MachineProfile

__all__ = ["GcodeReport", "ReadFilament", "check_gcode", "parse_gcode", "read_gcode"]

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)"
_META = re.compile(
    r"; filament (\d+) layer=(\d+) radius=(\S+) active_fraction=(\S+) "
    r"active_material=(\S+) passive_material=(\S+)$"
)
_CURE = re.compile(rf"; UV cure after layer \d+: ({_NUM}) s by hand")
_TOL = 1e-6  # relative tolerance of limit checks on read-back numbers


@dataclass(frozen=True)
class ReadFilament:
    """One filament read back from G-code.

    Attributes
    ----------
    program
        The rebuilt :class:`PrintProgram` in program coordinates (the last vertex speed repeats
        the last move's); material names and radius from the ``; filament`` comment, or the
        :class:`PrintProgram` defaults where a program has none.
    pressure
        Set-point (psi) of each driven channel, ``{"active": 30.0, "passive": 20.0}``; NaN
        where only a valve is switched.
    prime_dwell, release_dwell
        Dwells (s) after pressure-on and after pressure-off.
    line
        Line number (1-based) of its first print move.
    """

    program: PrintProgram
    pressure: dict[str, float]
    prime_dwell: float
    release_dwell: float
    line: int


@dataclass(frozen=True)
class GcodeReport:
    """What :func:`check_gcode` found: filaments, extremes and the time estimate.

    Attributes
    ----------
    filaments
        One :class:`ReadFilament` per filament.
    moves
        Number of motion blocks.
    max_rotation
        Highest rotation rate (rad/s) of any move, travel included.
    feed_range
        Lowest and highest print feed (mm/s).
    max_start_turns
        Largest magnitude of the rotary word at a filament start, in turns.
    time
        Estimated run time (s): feed moves at their F, rapids at ``travel_feed``, dwells.
    """

    filaments: list[ReadFilament]
    moves: int
    max_rotation: float
    feed_range: tuple[float, float]
    max_start_turns: float
    time: float


def _template_regex(template: str) -> re.Pattern[str]:
    parts = []
    for literal, name, _spec, _conv in string.Formatter().parse(template):
        parts.append(re.escape(literal))
        if name is not None:
            parts.append(rf"(?P<{name}>{_NUM})")
    return re.compile("".join(parts) + "$")


@dataclass
class _State:
    m: MachineProfile
    # x, y, z unknown at the start; the rotary axis reads 0 (stated in every header)
    pos: list[float] = field(default_factory=lambda: [math.nan, math.nan, math.nan, 0.0])
    feed: float | None = None
    setpoint: dict[int, float] = field(default_factory=dict)
    on: dict[int, bool] = field(default_factory=dict)
    meta: re.Match[str] | None = None
    current: dict[str, Any] | None = None
    last: ReadFilament | None = None
    pending_dwell: float = 0.0
    out: list[ReadFilament] = field(default_factory=list)
    moves: int = 0
    max_rotation: float = 0.0
    feeds: list[float] = field(default_factory=list)
    start_turns: float = 0.0
    time: float = 0.0

    @property
    def printing(self) -> bool:
        return any(self.on.values())


class _Reader:
    def __init__(self, machine: MachineProfile, *, require_metadata: bool) -> None:
        m = machine
        self.m = m
        self.require_metadata = require_metadata
        self.axes = {m.x_axis: 0, m.y_axis: 1, m.z_axis: 2, m.rotary_axis: 3}
        self.ports = {m.active_port: "active", m.passive_port: "passive"}
        self.dwell = _template_regex(m.dwell_template or "")
        self.setpoint = _template_regex(m.pressure_template) if m.pressure_template else None
        self.valve_on = _template_regex(m.valve_on_template) if m.valve_on_template else None
        self.valve_off = _template_regex(m.valve_off_template) if m.valve_off_template else None
        self.uv = {t for t in (m.uv_on_template, m.uv_off_template) if t}
        self.word = re.compile(rf"([A-Z])({_NUM})$")
        self.s = _State(m)

    # ------------------------------------------------------------------ helpers
    def fail(self, no: int, why: str, line: str) -> GcodeParseError:
        return GcodeParseError(f"line {no}: {why}: {line!r}")

    def limit(self, no: int, what: str, key: str) -> MachineLimitError:
        return MachineLimitError(
            f"line {no}: {what} on machine {self.m.name!r} (machine profile key '{key}')"
        )

    def port(self, no: int, line: str, value: str) -> int:
        port = int(float(value))
        if port not in self.ports:
            raise self.fail(no, f"unknown pressure port {port}", line)
        return port

    def set_pressure(self, no: int, line: str, port: int, psi: float, switches: bool) -> None:
        """Record a set-point; with ``switches`` a set-point of 0 turns the channel off."""
        m = self.m
        if not (m.min_pressure * (1 - _TOL) - 1e-9 <= psi <= m.max_pressure * (1 + _TOL)):
            key = "max_pressure" if psi > m.max_pressure else "min_pressure"
            raise self.limit(no, f"pressure {psi:g} psi outside the machine's range", key)
        changed = psi != self.s.setpoint.get(port) and not (switches and psi == 0)
        if self.s.current is not None and self.s.on.get(port) and changed:
            raise self.fail(no, "pressure changed in the middle of a filament", line)
        self.s.setpoint[port] = psi

    def switch(self, no: int, line: str, port: int, on: bool) -> None:
        s = self.s
        if s.current is not None and on and not s.on.get(port):
            raise self.fail(no, "channel switched on in the middle of a filament", line)
        s.on[port] = on
        if not s.printing:
            self.close(no, line)

    # ------------------------------------------------------------------ commands
    def pressure(self, no: int, line: str) -> bool:
        m = self.m
        if line.startswith("Call "):  # a serial call takes time (profile key pressure_call_s)
            self.s.time += m.pressure_call_s
        if m.pressure_idiom == "alicat":
            pm = re.fullmatch(rf"Call setAlicatPress P(\d+) Q({_NUM})", line)
            if pm:
                port, psi = self.port(no, line, pm[1]), float(pm[2])
                self.set_pressure(no, line, port, psi, True)
                self.switch(no, line, port, psi > 0)
            return pm is not None
        if m.pressure_idiom == "nordson":
            pm = re.fullmatch(rf"Call setPress P(\d+) Q({_NUM})", line)
            if pm:
                port = self.port(no, line, pm[1])
                if self.s.on.get(port):
                    raise self.fail(no, "set-point changed while dispensing", line)
                self.set_pressure(no, line, port, float(pm[2]), False)
                return True
            pm = re.fullmatch(r"Call setDispense P(\d+) Q([01])", line)
            if pm:  # rotomorph's explicit state
                self.switch(no, line, self.port(no, line, pm[1]), pm[2] == "1")
                return True
            pm = re.fullmatch(r"Call togglePress P(\d+)", line)
            if pm:  # mecode's toggle (read, never written: it depends on the dispenser's state)
                port = self.port(no, line, pm[1])
                self.switch(no, line, port, not self.s.on.get(port, False))
            return pm is not None
        for regex, kind in ((self.setpoint, "set"), (self.valve_on, "on"), (self.valve_off, "off")):
            pm = regex.fullmatch(line) if regex is not None else None
            if pm is None:
                continue
            groups = pm.groupdict()
            port = self.port(no, line, groups["port"]) if "port" in groups else m.active_port
            if kind == "set":
                psi = _psi(m, groups)
                self.set_pressure(no, line, port, psi, self.valve_on is None)
                if self.valve_on is None:
                    self.switch(no, line, port, psi > 0)
            else:
                self.switch(no, line, port, kind == "on")
            return True
        return False

    def motion(self, no: int, line: str) -> None:
        m, s = self.m, self.s
        words = line.split()
        cmd = words[0]
        if cmd not in ("G0", "G1"):
            raise self.fail(no, "unexpected command", line)
        new = list(s.pos)
        feed = None
        s.last = None  # a dwell after this is no longer the previous filament's release
        for w in words[1:]:
            wm = self.word.match(w)
            if not wm:
                raise self.fail(no, f"malformed word {w!r}", line)
            letter, value = wm[1], float(wm[2])
            if letter in self.axes:
                new[self.axes[letter]] = value
            elif letter == "F":
                if value <= 0:
                    raise self.fail(no, "feed must be > 0", line)
                feed = value / m.feed_scale
            else:
                raise self.fail(no, f"unexpected word {w!r}", line)
        moved = [not (a == b or (a != a and b != b)) for a, b in zip(new, s.pos, strict=True)]
        if not any(moved):
            if cmd == "G1" and feed is not None and len(words) == 2 and m.dialect == "aerotech":
                s.feed = feed  # mecode's feed(): a modal F on its own line
                return
            raise self.fail(no, "block without motion", line)
        self.envelope(no, new)
        s.moves += 1
        travel = cmd == "G1" and m.dialect == "aerotech" and not s.printing and not moved[3]
        if travel and feed is None and s.feed is not None:  # mecode's travel: G1 at travel feed
            if s.feed > max(m.max_feed, m.travel_feed) * (1 + _TOL):
                raise self.limit(
                    no, f"travel feed {s.feed:g} mm/s above the maximum", "travel_feed"
                )
            distance = math.dist(new[:3], s.pos[:3])
            s.time += distance / s.feed if math.isfinite(distance) else 0.0
            s.pos = new
            return
        if cmd == "G0":
            if moved[3]:
                raise self.fail(
                    no, "rotary word on a rapid G0 (its rotation rate is unknown)", line
                )
            if s.printing:
                raise self.fail(no, "travel move (G0) with a pressure on", line)
            if m.dialect == "marlin" and feed is None:
                raise self.fail(no, "travel without F (marlin moves at the last feed)", line)
            distance = math.dist(new[:3], s.pos[:3])
            s.time += distance / m.travel_feed if math.isfinite(distance) else 0.0
            s.pos = new
            return
        if feed is None:
            if m.dialect != "aerotech":
                raise self.fail(no, "G1 without F (this dialect writes F on every move)", line)
            feed = s.feed
        if feed is None:
            raise self.fail(no, "G1 before any feed was set", line)
        s.feed = feed
        if any(math.isnan(v) for v in s.pos):
            raise self.fail(no, "feed move from an unknown position", line)
        length = math.dist(new[:3], s.pos[:3])
        turn = abs(new[3] - s.pos[3]) / abs(m.rotary_scale)
        if length == 0.0:
            raise self.fail(no, "rotary-only move (its feed units are ambiguous)", line)
        rate = turn * feed / length
        s.max_rotation = max(s.max_rotation, rate)
        if rate > m.max_rotation * (1 + _TOL):
            raise self.limit(
                no, f"rotation {rate:.6g} rad/s exceeds {m.max_rotation:.6g} rad/s", "max_rotation"
            )
        printing = s.printing
        top = max(m.max_feed, m.travel_feed) if not printing else m.max_feed
        if feed > top * (1 + _TOL):
            raise self.limit(no, f"feed {feed:g} mm/s above the maximum", "max_feed")
        if feed < m.min_feed * (1 - _TOL):
            raise self.limit(no, f"feed {feed:g} mm/s below the minimum", "min_feed")
        s.time += length / feed
        if not printing:
            if moved[0] or moved[1]:
                raise self.fail(no, "print move (G1) with every pressure channel off", line)
            s.pos = new
            return
        self.extend(no, line, new, feed)
        s.pos = new

    def extend(self, no: int, line: str, new: list[float], feed: float) -> None:
        s, m = self.s, self.m
        if s.current is None:
            if s.meta is None and self.require_metadata:
                raise self.fail(no, "print move without a '; filament ...' comment", line)
            if abs(s.pos[3]) > m.turn * (1 + _TOL):
                raise self.limit(
                    no,
                    f"rotary word {s.pos[3]:g} exceeds one turn at a filament start",
                    "rotary_rebase",
                )
            s.start_turns = max(s.start_turns, abs(s.pos[3]) / m.turn)
            s.current = {
                "points": [s.pos[:3]],
                "angle": [s.pos[3]],
                "speed": [],
                "line": no,
                "prime": s.pending_dwell,  # consumed below
                "pressure": {
                    self.ports[p]: s.setpoint.get(p, math.nan) for p, on in s.on.items() if on
                },
            }
            s.pending_dwell = 0.0
        s.feeds.append(feed)
        s.current["points"].append(new[:3])
        s.current["angle"].append(new[3])
        s.current["speed"].append(feed)

    def close(self, no: int, line: str) -> None:
        s, m = self.s, self.m
        cur = s.current
        if cur is None:
            return
        kwargs: dict[str, Any] = {}
        if s.meta is not None:
            _, layer, radius, frac, act, pas = s.meta.groups()
            kwargs = dict(
                radius=float(radius),
                active_fraction=float(frac),
                active_material=act,
                passive_material=pas,
                layer=int(layer),
            )
        speed = cur["speed"] + [cur["speed"][-1]]
        try:
            prog = PrintProgram(
                np.array(cur["points"]),
                np.array(speed),
                np.array(cur["angle"]) / m.rotary_scale,
                **kwargs,
            )
        except InvalidParameterError as exc:
            raise self.fail(no, f"filament is not a valid PrintProgram ({exc})", line) from exc
        s.last = ReadFilament(prog, cur["pressure"], cur["prime"], 0.0, cur["line"])
        s.out.append(s.last)
        s.current, s.meta = None, None

    def other(self, no: int, line: str) -> bool:
        s, m = self.s, self.m
        dm = self.dwell.fullmatch(line)
        if dm:
            g = dm.groupdict()
            seconds = float(g["s"]) if "s" in g else float(g["ms"]) / 1000.0
            s.time += seconds
            if s.current is None and s.printing:
                s.pending_dwell = seconds  # prime
            elif s.current is None and s.last is not None and not s.printing:
                s.out[-1] = _with_release(s.last, seconds)  # right after pressure-off
                s.last = None
            elif s.current is not None:
                raise self.fail(no, "dwell in the middle of a filament", line)
            return True
        if line in self.uv or line == m.pause_template:
            if s.printing:
                raise self.fail(no, "UV line or pause with a pressure on", line)
            return True
        gm = re.fullmatch(rf"G92 {m.rotary_axis}({_NUM})", line)
        if gm:
            if s.printing:
                raise self.fail(no, "G92 with a pressure on", line)
            if m.controller == "klipper":
                raise self.fail(
                    no, "G92 with a rotary word on Klipper (its G92 would zero X, Y and Z)", line
                )
            s.pos[3] = float(gm[1])
            return True
        return False

    # ------------------------------------------------------------------ driver
    def run(self, text: str) -> GcodeReport:
        """Read ``text``; a rotomorph program's header names the machine it was written for,
        and an error on a program written for another machine says so."""
        lines = [ln.rstrip() for ln in text.splitlines()]
        first = 0  # first line that is not a comment
        written: dict[str, tuple[int, str]] = {}
        while first < len(lines) and lines[first].startswith(";"):
            found = re.match(r"; (dialect|machine): ([^,]+),", lines[first])
            if found:
                written[found[1]] = (first + 1, found[2])
            first += 1
        dialect = written.get("dialect")
        if dialect is not None and dialect[1] != self.m.dialect:
            raise GcodeParseError(
                f"line {dialect[0]}: the program was written for the {dialect[1]!r} dialect, the "
                f"machine profile {self.m.name!r} is {self.m.dialect!r}; check it against the "
                "profile it was written for (its '; machine:' header line)"
            )
        try:
            return self._read(lines, first)
        except GcodeParseError as err:
            machine = written.get("machine")
            if machine is None or lines[machine[0] - 1].startswith(f"; machine: {self.m.name}, "):
                raise
            raise GcodeParseError(
                f"{err} (the program was written for another machine, header line "
                f"{machine[0]}: {lines[machine[0] - 1][2:]!r}; the profile is {self.m.name!r})"
            ) from None

    def _read(self, lines: list[str], first: int) -> GcodeReport:
        m, s = self.m, self.s
        i = first
        # rotomorph's own programs carry their subroutines; a lab's (mecode) program may not
        ours = bool(lines) and lines[0].startswith("; rotomorph G-code")
        library = ours or any(ln.startswith("DVAR ") for ln in lines[: first + 2])
        header = [*(gcode_aerotech.declarations(m) if library else ()), *m.header_lines]
        for start in range(first, -1, -1):  # the header block may itself open with comments
            if lines[start : start + len(header)] == header:
                i = start + len(header)
                break
        else:
            raise self.fail(first + 1, "the profile's header_lines are missing", "<header>")
        setup, end_lines = list(m.setup_lines or ()), list(m.end_lines or ())
        got = lines[i : i + len(setup)]
        if got != setup:
            raise self.fail(i + 1, f"expected the profile's setup_lines {setup}", str(got))
        i += len(setup)
        end = len(lines)
        footer = [*(gcode_aerotech.subroutines(m) if library else ()), *m.footer_lines]
        if footer:
            got = lines[end - len(footer) :]
            if got != footer:
                what = (
                    "footer_lines"
                    if got[-len(m.footer_lines) or len(got) :] != list(m.footer_lines)
                    else "pressure subroutines"
                )
                raise self.fail(end, f"the profile's {what} are missing", "<end of file>")
            end -= len(footer)
        tail = [k for k in range(i, end) if lines[k].strip() and not lines[k].startswith(";")]
        n_end = len(end_lines)
        if [lines[k].strip() for k in tail[len(tail) - n_end :]] != end_lines or (
            n_end and len(tail) < n_end
        ):
            raise self.fail(end, f"the program must end with {end_lines}", "<end>")
        stop = tail[len(tail) - n_end] if n_end else end
        for k in range(i, stop):
            no, line = k + 1, lines[k].strip()
            if not line:
                continue
            if line.startswith(";"):
                cure = _CURE.match(line)
                if cure:  # the operator's cure at a pause, as the writer counts it
                    s.time += float(cure[1])
                mm = _META.match(line)
                if mm:
                    if s.current is not None or s.meta is not None:
                        raise self.fail(no, "filament comment inside another filament", line)
                    s.meta = mm
                continue
            if ";" in line or "(" in line:
                raise self.fail(no, "comment after a command (not written by rotomorph)", line)
            if self.pressure(no, line) or self.other(no, line):
                continue
            self.motion(no, line)
            if s.current is not None and not line.startswith("G1"):
                raise self.fail(no, "unexpected command inside a filament", line)
        if s.current is not None or s.printing:
            raise self.fail(len(lines), "file ends with a pressure on", "<end of file>")
        feeds = (min(s.feeds), max(s.feeds)) if s.feeds else (math.nan, math.nan)
        return GcodeReport(s.out, s.moves, s.max_rotation, feeds, s.start_turns, s.time)

    def envelope(self, no: int, new: list[float]) -> None:
        m = self.m
        xyz = new[:3]
        if any(v < lo - 1e-9 for v, lo in zip(xyz, m.envelope_min, strict=True)):
            raise self.limit(no, f"position {xyz} mm below the envelope", "envelope_min")
        if any(v > hi + 1e-9 for v, hi in zip(xyz, m.envelope_max, strict=True)):
            raise self.limit(no, f"position {xyz} mm above the envelope", "envelope_max")


def _psi(m: MachineProfile, groups: dict[str, str]) -> float:
    if "psi" in groups:
        return float(groups["psi"])
    if "fraction" in groups:
        return float(groups["fraction"]) * m.max_pressure
    return float(groups["pwm"]) / 255.0 * m.max_pressure


def _with_release(f: ReadFilament, seconds: float) -> ReadFilament:
    return ReadFilament(f.program, f.pressure, f.prime_dwell, seconds, f.line)


def check_gcode(
    text: str, machine: MachineProfile, *, require_metadata: bool = False
) -> GcodeReport:
    """Read ``text`` strictly as ``machine``'s controller would and check it (module docstring).

    Raises
    ------
    GcodeParseError
        On the first unexpected line, with its number.
    MachineLimitError
        On the first move or set-point outside the profile, naming the profile key.
    """
    return _Reader(machine, require_metadata=require_metadata).run(text)


def parse_gcode(text: str, machine: MachineProfile) -> list[ReadFilament]:
    """Filaments of a rotomorph program ``text`` for ``machine`` (metadata comments required)."""
    return check_gcode(text, machine, require_metadata=True).filaments


def read_gcode(path: str | FilePath, machine: MachineProfile) -> list[ReadFilament]:
    """Read a G-code file written for ``machine``; see :func:`parse_gcode`."""
    return parse_gcode(FilePath(path).read_text(encoding="utf-8"), machine)
