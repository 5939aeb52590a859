"""G-code writer for rotational multimaterial printing.

Layout of the emitted program (dialects and idioms: :mod:`rotomorph.io.machine`)::

    ; header: tool, design sha256, machine and its limits, dialect, units, axes, rotary
    ;         convention, pressure channels, estimated time
    <header_lines>                verbatim (e.g. an A3200 DVAR block), optional
    <setup_lines>                 G71 G76 G90 | G21 G90 G94 | G21 G90
    ; layer 0
    ; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=…
    G0 Z<travel>                  lift: `lift` above everything printed so far
    G0 X.. Y..                    travel at that height (no rotary word: G0 rates are unknown)
    [G92 C<angle mod 360>]        re-base the rotary word (never more than a turn between
                                  filaments)
    G1 Z<z0> C<start> F<f>        lower while turning to the start angle, f within max_rotation
    <pressure on>                 only the channels the filament uses (pure active: one)
    [G4 <prime dwell>]
    G1 X.. Y.. [Z..] C.. [F..]    one move per edge, rotary in the same block, cumulative angle
    ...
    <pressure off>
    [G4 <release dwell>]
    ; end filament 0
    [lift, UV cure dwell after each layer]
    G0 Z<top + lift>
    [G92 C<restored>] <end_lines> <footer_lines>

Precision: positions and angles are written with 6 decimals (trailing zeros dropped), feeds
with 10 significant digits; each move's angle increment is the design's dα/ds times the
*written* move length, so dα/ds · v = ω holds for the numbers in the file on every move (to the
last decimal of the angle word), not only for the design's floats.

Safety: nothing is written unless every vertex and travel lies in the envelope, every feed is
within [min_feed, max_feed], every rotary move (travel included) within max_rotation, every
pressure within the profile's range, and every name one word of printable ASCII; the error names
the machine-profile key to change (:class:`~rotomorph.errors.MachineLimitError`).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path as FilePath

import numpy as np

import rotomorph
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError, MachineLimitError, MaterialError
from rotomorph.io import gcode_aerotech
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.design_limits import MAX_LAYER_CURE_S
from rotomorph.io.machine import MachineProfile, check_line, fill_template
from rotomorph.io.print_order import machine_order
from rotomorph.materials.material import get_material, known_materials
from rotomorph.materials.parameter_set import MaterialSet

__all__ = [
    "MAX_LINE",
    "PLACEHOLDER_SETTINGS",
    "Process",
    "check_materials",
    "gcode_text",
    "placeholder_settings",
    "pressure_lines",
    "programs_sha256",
    "write_gcode",
]

_EPS = 1e-9
_DIGITS = 6  # decimals of position and angle words (mm, deg or rad)
#: Longest line written (characters). LinuxCNC's interpreter refuses lines over 252 characters
#: (comments included); every dialect is kept below this.
MAX_LINE = 250
#: Process settings that are placeholders unless a design (or the caller) sets them.
PLACEHOLDER_SETTINGS = ("active_pressure", "passive_pressure", "prime_dwell", "release_dwell")


class _Num(float):
    """A float that formats without trailing zeros when a template gives no format spec."""

    def __format__(self, spec: str) -> str:
        return _num(self) if spec == "" else float.__format__(self, spec)


def _num(x: float, digits: int = _DIGITS) -> str:
    """``x`` with at most ``digits`` decimals, trailing zeros dropped, never ``-0``."""
    s = f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _feed(x: float) -> str:
    """A feed word's number: 10 significant digits, positional (never ``0``, never ``1e-05``)."""
    return np.format_float_positional(x, precision=10, unique=True, fractional=False, trim="-")


@dataclass(frozen=True)
class Process:
    """How one filament is extruded.

    Parameters
    ----------
    active_pressure, passive_pressure
        Set-points (psi) of the active and passive channels. Only the channels a filament uses
        are driven: ``active_fraction = 1`` drives the active channel alone, ``0`` the passive
        one alone (the other pressure is then ignored).
    prime_dwell
        Dwell after pressure-on before the first move (s), so the ink reaches the tip.
    release_dwell
        Dwell after pressure-off before the lift (s), so the flow stops before the nozzle moves.
    placeholders
        Names of the settings above that nobody set (defaults, not the lab's values): the
        program's header flags them and ``rotomorph gcode`` says so on stderr.
    """

    active_pressure: float = 30.0
    passive_pressure: float = 30.0
    prime_dwell: float = 0.0
    release_dwell: float = 0.0
    placeholders: tuple[str, ...] = field(default=(), compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "placeholders", tuple(self.placeholders))
        unknown = set(self.placeholders) - set(PLACEHOLDER_SETTINGS)
        if unknown:
            raise InvalidParameterError(
                "Process.placeholders",
                f"must name settings of {PLACEHOLDER_SETTINGS}; got {sorted(unknown)}",
            )
        for name in ("active_pressure", "passive_pressure", "prime_dwell", "release_dwell"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | float) or not math.isfinite(v):
                raise InvalidParameterError(
                    f"Process.{name}", f"must be a finite number; got {v!r}"
                )
            if v < 0:
                raise InvalidParameterError(f"Process.{name}", f"must be >= 0; got {v!r}")

    @classmethod
    def from_flow(
        cls,
        program: PrintProgram,
        *,
        active_conductance: float | None,
        passive_conductance: float | None,
        prime_dwell: float = 0.0,
        release_dwell: float = 0.0,
    ) -> Process:
        r"""Pressures from a linear (Hagen–Poiseuille) flow model of each channel.

        The channels must together deliver the filament's volume rate
        :math:`Q = \bar v\,\pi R^2`, split by the active fraction φ:
        :math:`P_a = \bar v \pi R^2 \varphi / k_a` and
        :math:`P_p = \bar v \pi R^2 (1-\varphi) / k_p`, with :math:`\bar v` the filament's
        mean speed (length / duration, mm/s) and :math:`k` a channel's conductance
        (mm³/s per psi), which the lab measures for its ink and nozzle (a fit to its own
        extrusion tests, not a prediction). A channel the filament does not use gets 0.

        Raises
        ------
        InvalidParameterError
            A used channel without a conductance > 0.
        """
        rate = float(program.arc_length[-1]) / program.duration * np.pi * program.radius**2
        psi = {}
        for role, share, k in (
            ("active", program.active_fraction, active_conductance),
            ("passive", 1.0 - program.active_fraction, passive_conductance),
        ):
            if share <= 0:
                psi[role] = 0.0
            elif k is None or not (math.isfinite(k) and k > 0):
                raise InvalidParameterError(
                    f"{role}_conductance", f"must be > 0 mm^3/s per psi for a flow model; got {k}"
                )
            else:
                psi[role] = rate * share / k
        return cls(psi["active"], psi["passive"], prime_dwell, release_dwell)

    def channels(self, active_fraction: float) -> list[tuple[str, float]]:
        """``(role, psi)`` of the channels a filament with ``active_fraction`` drives."""
        out = []
        if active_fraction > 0:
            out.append(("active", float(self.active_pressure)))
        if active_fraction < 1:
            out.append(("passive", float(self.passive_pressure)))
        return out


def programs_sha256(programs: Sequence[PrintProgram]) -> str:
    """sha256 (hex) of the canonical JSON of ``programs`` (values rounded to 1e-9)."""

    def r(a: np.ndarray) -> list:
        return np.round(np.asarray(a, float), 9).tolist()

    data = [
        {
            "points": r(p.points),
            "speed": r(p.speed),
            "nozzle_angle": r(p.nozzle_angle),
            "radius": p.radius,
            "active_fraction": p.active_fraction,
            "active_material": p.active_material,
            "passive_material": p.passive_material,
            "layer": p.layer,
        }
        for p in programs
    ]
    blob = json.dumps(data, sort_keys=True, separators=(",", ":")).encode()
    return hashlib.sha256(blob).hexdigest()


def check_materials(programs: Sequence[PrintProgram], materials: MaterialSet | None = None) -> None:
    """Every material a program names must be known and be one printable word.

    The same check as ``rotomorph validate``: an ink of ``materials`` (the design's materials
    file) or, without one, a registered material (``get_material``); plus the text check of
    everything written into a program, so a name can neither be unknown nor inject a line.

    Raises
    ------
    MaterialError
        Unknown material, naming the program and role.
    InvalidParameterError
        A name that is not one word of printable ASCII.
    """
    for i, program in enumerate(programs):
        for role in ("active", "passive"):
            name = getattr(program, f"{role}_material")
            check_line(f"print program {i}: {role} material", name, token=True)
            try:
                mat = get_material(name) if materials is None else materials.material(name)
            except MaterialError:
                known = known_materials() if materials is None else materials.names()
                where = "" if materials is None else f" in materials {materials.name!r}"
                raise MaterialError(
                    f"print program {i}: {role} material",
                    f"unknown material {name!r}{where}; known: {', '.join(known)}",
                ) from None
            if mat.kind != role:
                raise MaterialError(
                    f"print program {i}: {role} material", f"{name!r} is a {mat.kind} material"
                )


def pressure_lines(m: MachineProfile, port: int, psi: float, on: bool) -> list[str]:
    """The lines that turn channel ``port`` on at ``psi`` (or off) in the profile's idiom."""
    if m.pressure_idiom == "alicat":
        return [f"Call setAlicatPress P{port} Q{_num(psi if on else 0.0, 3)}"]
    if m.pressure_idiom == "nordson":  # explicit states, never a blind toggle
        if not on:
            return [f"Call setDispense P{port} Q0"]
        return [f"Call setPress P{port} Q{_num(psi, 3)}", f"Call setDispense P{port} Q1"]
    values = {k: (_Num(v) if k != "pwm" else v) for k, v in m.pressure_values(psi).items()}
    setpoint = fill_template(m.pressure_template or "", port=port, **values)
    if not m.valve_on_template:
        off = {k: (_Num(v) if k != "pwm" else v) for k, v in m.pressure_values(0.0).items()}
        return [setpoint if on else fill_template(m.pressure_template or "", port=port, **off)]
    valve = fill_template(m.valve_on_template if on else m.valve_off_template or "", port=port)
    if not on:
        return [valve]
    return ([setpoint] if m.pressure_template else []) + [valve]


def _dwell(m: MachineProfile, seconds: float) -> str:
    return fill_template(m.dwell_template or "", s=_Num(seconds), ms=round(seconds * 1000))


def _as_process(process: Process | Sequence[Process], n: int) -> list[Process]:
    if isinstance(process, Process):
        return [process] * n
    procs = list(process)
    if len(procs) != n or not all(isinstance(p, Process) for p in procs):
        raise InvalidParameterError(
            "process", f"must be one Process or one per program ({n}); got {len(procs)}"
        )
    return procs


def _limit(where: str, what: str, key: str, hint: str) -> MachineLimitError:
    return MachineLimitError(f"{where}: {what}; {hint} (machine profile key '{key}')")


@dataclass
class _Writer:
    """Emits lines while tracking the machine state (position, feed, angle, time)."""

    m: MachineProfile
    lines: list[str] = field(default_factory=list)
    xyz: np.ndarray | None = None
    angle: float = 0.0  # current rotary word (program coordinates)
    shift: float = 0.0  # total G92 re-basing of the rotary word
    feed: float | None = None  # modal F (aerotech), mm/s
    time: float = 0.0
    wound: float = 0.0  # largest |physical nozzle angle| (rotary words + G92 shifts)
    turned: float = 0.0  # total |rotation| of the nozzle (rotary-word units)

    def emit(self, *lines: str) -> None:
        self.lines.extend(lines)

    def dwell(self, seconds: float) -> None:
        if seconds > 0:
            self.emit(_dwell(self.m, seconds))
            self.time += seconds

    def _words(self, xyz: np.ndarray, angle: float | None, axes: str) -> str:
        m = self.m
        letters = {"x": m.x_axis, "y": m.y_axis, "z": m.z_axis}
        words = [f"{letters[a]}{_num(xyz['xyz'.index(a)])}" for a in axes]
        if angle is not None:
            words.append(f"{m.rotary_axis}{_num(angle)}")
        return " ".join(words)

    def rapid(self, xyz: np.ndarray, axes: str) -> None:
        """A travel move (no rotary word); none if already there.

        ``G0`` on LinuxCNC (the controller's rapid rate), ``G0 … F<travel>`` on Marlin-like
        firmware (which run G0 at the last feed), ``G1`` at ``travel_feed`` on Aerotech (as
        mecode travels: an A3200 ``G0`` runs at its own rapid rate, not the profile's).
        """
        m = self.m
        if self.xyz is not None and all(
            _num(a) == _num(b) for a, b in zip(xyz, self.xyz, strict=True)
        ):
            return
        if m.dialect == "aerotech":
            if self.feed != m.travel_feed:
                self.emit(f"G1 F{_feed(m.travel_feed)}")
                self.feed = m.travel_feed
            self.emit(f"G1 {self._words(xyz, None, axes)}")
        else:
            f = f" F{_feed(m.travel_feed * m.feed_scale)}" if m.dialect == "marlin" else ""
            self.emit(f"G0 {self._words(xyz, None, axes)}{f}")
        if self.xyz is not None:
            distance = float(np.linalg.norm(xyz - self.xyz))
            self.time += distance / m.travel_feed if math.isfinite(distance) else 0.0
        self.xyz = xyz.copy()

    def pressure(self, port: int, psi: float, on: bool) -> None:
        """Pressure lines of one channel; serial calls cost the profile's pressure_call_s."""
        lines = pressure_lines(self.m, port, psi, on)
        self.emit(*lines)
        self.time += self.m.pressure_call_s * sum(ln.startswith("Call ") for ln in lines)

    def linear(self, xyz: np.ndarray, angle: float, speed: float, axes: str) -> None:
        """A feed move with the rotary word; F on its own line (aerotech) or in the block."""
        m = self.m
        if m.dialect == "aerotech":
            if self.feed != speed:
                self.emit(f"G1 F{_feed(speed)}")
            self.emit(f"G1 {self._words(xyz, angle, axes)}")
        else:
            self.emit(f"G1 {self._words(xyz, angle, axes)} F{_feed(speed * m.feed_scale)}")
        self.feed = speed
        assert self.xyz is not None
        self.time += math.dist(xyz, self.xyz) / speed
        self.turned += abs(angle - self.angle)
        self.wound = max(self.wound, abs(angle + self.shift))
        self.xyz, self.angle = xyz.copy(), angle


def _written_angles(prog: PrintProgram, pts: np.ndarray, start: float, scale: float) -> np.ndarray:
    """Rotary words along ``pts`` from ``start``: the design's dα/ds times the written lengths."""
    ds_design = prog.path.edge_lengths
    ds_written = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    rate = np.diff(prog.nozzle_angle) / ds_design * scale  # words per mm
    return np.round(start + np.concatenate([[0.0], np.cumsum(rate * ds_written)]), _DIGITS)


def _check_program(
    k: int, prog: PrintProgram, pts: np.ndarray, words: np.ndarray, m: MachineProfile
) -> None:
    where = f"program {k}"
    lo, hi = np.array(m.envelope_min), np.array(m.envelope_max)
    out = np.flatnonzero(((pts < lo - _EPS) | (pts > hi + _EPS)).any(axis=1))
    if out.size:
        i = int(out[0])
        key = "envelope_max" if (pts[i] > hi + _EPS).any() else "envelope_min"
        raise _limit(
            where,
            f"vertex {i} at {np.round(pts[i], 4).tolist()} mm (z_offset {m.z_offset:g} mm "
            f"included) leaves the envelope {list(m.envelope_min)}..{list(m.envelope_max)} mm "
            f"of machine {m.name!r}",
            key,
            "translate the design or change",
        )
    ds = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(ds <= 0):
        i = int(np.flatnonzero(ds <= 0)[0])
        raise InvalidParameterError(
            "programs", f"{where}: move {i} is shorter than the written resolution 1e-6 mm"
        )
    feed = prog.speed[:-1]
    fast = np.flatnonzero(feed > m.max_feed * (1 + 1e-12))
    if fast.size:
        i = int(fast[0])
        raise _limit(
            where,
            f"speed {feed[i]:g} mm/s at vertex {i} exceeds the maximum feed {m.max_feed:g} mm/s",
            "max_feed",
            "slow the design or raise",
        )
    slow = np.flatnonzero(feed < m.min_feed * (1 - 1e-12))
    if slow.size:
        i = int(slow[0])
        raise _limit(
            where,
            f"speed {feed[i]:g} mm/s at vertex {i} is below the minimum feed {m.min_feed:g} mm/s",
            "min_feed",
            "speed the design up or lower",
        )
    rotation = np.abs(np.diff(words) / m.rotary_scale) / ds * feed
    spin = np.flatnonzero(rotation > m.max_rotation * (1 + 1e-9))
    if spin.size:
        i = int(spin[0])
        raise _limit(
            where,
            f"nozzle rotation {rotation[i]:.4g} rad/s on the move from vertex {i} exceeds the "
            f"maximum {m.max_rotation:.4g} rad/s",
            "max_rotation",
            f"slow down, spread each active-side flip over flip_length >= "
            f"{math.pi * feed[i] / m.max_rotation:.2g} mm (pi * v / max_rotation at "
            f"v = {feed[i]:g} mm/s), or raise",
        )


def _check_process(k: int, prog: PrintProgram, proc: Process, m: MachineProfile) -> None:
    for role, psi in proc.channels(prog.active_fraction):
        if not (m.min_pressure <= psi <= m.max_pressure):
            raise _limit(
                f"program {k}",
                f"{role} pressure {psi:g} psi outside [{m.min_pressure:g}, {m.max_pressure:g}] psi",
                "max_pressure" if psi > m.max_pressure else "min_pressure",
                "change the design's pressure or",
            )
        if psi <= 0:
            raise InvalidParameterError(
                f"program {k}: {role}_pressure",
                f"is 0 psi but active_fraction {prog.active_fraction:g} needs the {role} "
                "channel; set a pressure > 0",
            )


def _travel_height(m: MachineProfile, top: float, *zs: float) -> float:
    z = max(top, *zs) + m.lift
    if z > m.envelope_max[2] + _EPS:
        raise MachineLimitError(
            f"travel height {z:.4g} mm (lift {m.lift:g} mm above the highest point printed so "
            f"far) exceeds the envelope's z maximum {m.envelope_max[2]:g} mm; lower 'lift' or "
            "raise 'envelope_max' in the machine profile (machine profile key 'lift')"
        )
    return z


def _materials_line(materials: MaterialSet | None) -> list[str]:
    """The header line naming the materials file (its name, version and content hash)."""
    if materials is None:
        return []
    line = f"; materials: {materials.name} version {materials.version} sha256 {materials.sha256}"
    check_line("materials", line)
    return [line]


def _header(
    m: MachineProfile,
    n: int,
    layers: int,
    design_hash: str,
    total: float,
    order: str,
    turns: list[float],
    w: _Writer,
    placeholders: dict[str, set[float]],
) -> list[str]:
    if m.is_builtin:
        origin = (
            "built-in default (no machine profile given: its envelope and limits are "
            "assumptions; pass --machine FILE for your printer)"
        )
    else:
        origin = f"profile {m.source}"
    f_unit = "mm/s" if m.dialect == "aerotech" else "mm/min"
    dwell_unit = "ms" if "{ms}" in (m.dwell_template or "") else "s"  # as G4 P is written
    turn = "360 deg" if m.rotary_units == "deg" else "2pi rad"
    rebase = (
        f"re-based with G92 between filaments (restored at the end), |{m.rotary_axis}| <= {turn}"
        if m.rotary_rebase == "g92"
        else f"unwound while lowering to each filament, |{m.rotary_axis}| <= {turn}"
    )
    k_max = int(np.argmax(np.abs(turns)))
    wound = w.wound / m.turn
    if m.continuous_rotation:
        said = "the built-in default assumes" if m.is_builtin else "the profile says it has"
        hoses = (
            f"the nozzle winds up to {wound:.1f} turns: {said} a rotary union "
            "(continuous_rotation = true)"
        )
    else:
        hoses = (
            f"no rotary union (continuous_rotation = false): unwound on every travel, at most "
            f"{wound:.1f} turns wound, limit {m.max_turns:g} per filament (max_turns)"
        )
    lines = [
        "; rotomorph G-code (rotational multimaterial printing)",
        f"; tool: rotomorph {rotomorph.__version__}",
        f"; design-sha256: {design_hash}",
        f"; machine: {m.name}, {origin}",
        f"; controller: {m.controller}",
        f"; limits: envelope {list(m.envelope_min)}..{list(m.envelope_max)} mm, feed "
        f"{m.min_feed:g}..{m.max_feed:g} mm/s, rotation <= {m.max_rotation:g} rad/s (travel "
        f"included), pressure {m.min_pressure:g}..{m.max_pressure:g} psi, lift {m.lift:g} mm",
        f"; dialect: {m.dialect}, pressure idiom {m.pressure_idiom}",
        f"; units: length mm, feed {f_unit}, rotary {m.rotary_units}, pressure psi, dwell "
        f"{dwell_unit}",
        f"; axes: {m.x_axis}=x {m.y_axis}=y {m.z_axis}=z (design z + z_offset {m.z_offset:g} "
        "mm; Z 0 = substrate surface in the active work offset)",
        f"; rotary: {m.rotary_axis} = nozzle angle of the active half, counter-clockwise from +x "
        f"seen from above times sign {m.rotary_sign:+d}",
        f";   must read 0 with the active half toward +x at the start; cumulative within a "
        f"filament, {rebase}",
        f"; nozzle turns (physical): up to {abs(turns[k_max]):.1f} in one filament (filament "
        f"{k_max}), {w.turned / m.turn:.1f} turned in all (travel included)",
        f";   {hoses}",
        f"; pressure channels: active port {m.active_port}, passive port {m.passive_port}",
        f"; filaments: {n}, layers: {layers}, order: {order}",
        f"; estimated print time: {total:.1f} s",
    ]
    if placeholders:
        units = {"active_pressure": "psi", "passive_pressure": "psi"}
        said = ", ".join(
            f"{k} {'/'.join(f'{v:g}' for v in sorted(vals))} {units.get(k, 's')}"
            for k, vals in placeholders.items()
        )
        lines += [
            f"; PLACEHOLDER values (defaults, not set by the design): {said}",
            ";   set them in the design's [nozzle] table (or per filament) before printing",
        ]
    return lines


def placeholder_settings(process: Process | Sequence[Process] | None) -> list[str]:
    """Names of the process settings that are placeholders in ``process`` (None: all)."""
    if process is None:
        return list(PLACEHOLDER_SETTINGS)
    procs = [process] if isinstance(process, Process) else list(process)
    return [k for k in PLACEHOLDER_SETTINGS if any(k in p.placeholders for p in procs)]


def plan_programs(
    programs: Sequence[PrintProgram], machine: MachineProfile, *, serpentine: bool = True
) -> list[PrintProgram]:
    """The programs as :func:`gcode_text` prints them: serpentine, z offset (mm) applied."""
    return machine_order(
        programs,
        serpentine=serpentine,
        max_rotation=machine.max_rotation,
        z_offset=machine.z_offset,
    )


def gcode_text(
    programs: Sequence[PrintProgram],
    machine: MachineProfile,
    *,
    process: Process | Sequence[Process] | None = None,
    layer_cure_s: float = 0.0,
    design_hash: str | None = None,
    serpentine: bool = True,
    materials: MaterialSet | None = None,
) -> str:
    """G-code for ``programs`` on ``machine`` (pure; see module docstring for the layout).

    Parameters
    ----------
    programs
        Filaments in print order; layers must not decrease.
    machine
        The printer: limits, axes, dialect, pressure idiom.
    process
        Pressures and dwells, one :class:`Process` for all or one per program (default
        :class:`Process`: 30 psi on each channel used, no dwells, all flagged as placeholders
        in the header).
    layer_cure_s
        UV cure after each layer (s): a dwell between the profile's lamp commands, or a pause
        for the operator where the profile has none; 0 writes none.
    design_hash
        sha256 to record in the header; default :func:`programs_sha256` of ``programs``.
    serpentine
        Print a program backward when that avoids a return travel (:func:`plan_programs`).
    materials
        The design's materials file: the programs' inks must be its inks, and the header
        names it (name, version, sha256); ``None``: registered materials.

    Raises
    ------
    MachineLimitError
        Envelope (travel included), feed (minimum and maximum), rotation (travel included) or
        pressure limit exceeded; the message names the machine-profile key.
    MaterialError
        A material that ``rotomorph validate`` would refuse.
    InvalidParameterError
        No programs, decreasing layers, bad process settings or cure time, a name that is not
        one word of printable ASCII.
    """
    if len(programs) == 0:
        raise InvalidParameterError("programs", "needs at least one PrintProgram")
    layers = [p.layer for p in programs]
    if any(b < a for a, b in itertools.pairwise(layers)):
        raise InvalidParameterError("programs", "must be ordered by layer (non-decreasing)")
    if not (math.isfinite(layer_cure_s) and 0 <= layer_cure_s <= MAX_LAYER_CURE_S):
        raise InvalidParameterError(
            "layer_cure_s",
            f"must be a UV dwell per layer in [0, {MAX_LAYER_CURE_S:g}] s; got {layer_cure_s}",
        )
    if design_hash is not None and not re.fullmatch(r"[0-9a-f]{64}", design_hash):
        raise InvalidParameterError("design_hash", "must be a sha256 hex digest (64 characters)")
    check_materials(programs, materials)
    if process is None:
        process = Process(placeholders=PLACEHOLDER_SETTINGS)
    procs = _as_process(process, len(programs))
    m = machine
    printed = plan_programs(programs, m, serpentine=serpentine)
    placeholders: dict[str, set[float]] = {}
    for k, (prog, proc) in enumerate(zip(printed, procs, strict=True)):
        _check_process(k, prog, proc, m)
        used = {f"{role}_pressure" for role, _ in proc.channels(prog.active_fraction)}
        for name in proc.placeholders:
            if name in used or name.endswith("_dwell"):
                placeholders.setdefault(name, set()).add(float(getattr(proc, name)))

    w = _Writer(m)
    top = -math.inf
    current_layer: int | None = None
    turns: list[float] = []
    w.emit("; every pressure channel off before the first move (explicit states)")
    for port in (m.active_port, m.passive_port):
        w.pressure(port, 0.0, False)
    for k, (prog, proc) in enumerate(zip(printed, procs, strict=True)):
        pts = np.round(prog.points, _DIGITS)
        start = _start_word(w, prog, m)
        words = _written_angles(prog, pts, start, m.rotary_scale)
        _check_program(k, prog, pts, words, m)
        turns.append(float(words[-1] - words[0]) / m.turn)
        if not m.continuous_rotation and abs(turns[-1]) > m.max_turns * (1 + 1e-12):
            raise _limit(
                f"program {k}",
                f"the nozzle turns {abs(turns[-1]):.1f} times within this one filament, more "
                f"than the {m.max_turns:g} turns its hoses allow without a rotary union",
                "max_turns",
                "lower the design's rotation, set continuous_rotation = true if the machine has "
                "a rotary union, or raise",
            )
        zt = _travel_height(m, top, pts[0, 2], *([] if w.xyz is None else [w.xyz[2]]))
        if prog.layer != current_layer:
            if current_layer is not None and layer_cure_s > 0:
                w.rapid(np.array([*w.xyz[:2], zt]), "z")  # type: ignore[index]
                _cure(w, current_layer, layer_cure_s)
            current_layer = prog.layer
            w.emit(f"; layer {prog.layer}")
        w.emit(
            f"; filament {k} layer={prog.layer} radius={prog.radius!r} "
            f"active_fraction={prog.active_fraction!r} active_material={prog.active_material} "
            f"passive_material={prog.passive_material}",
            f"; filament {k} turns the nozzle {turns[-1]:+.2f} times",
        )
        _travel(w, k, pts[0], zt, start)
        for role, psi in proc.channels(prog.active_fraction):
            w.pressure(getattr(m, f"{role}_port"), psi, True)
        w.dwell(proc.prime_dwell)
        for i in range(1, len(pts)):
            axes = "xyz" if _num(pts[i, 2]) != _num(pts[i - 1, 2]) else "xy"
            w.linear(pts[i], float(words[i]), float(prog.speed[i - 1]), axes)
        for role, psi in proc.channels(prog.active_fraction):
            w.pressure(getattr(m, f"{role}_port"), psi, False)
        w.dwell(proc.release_dwell)
        w.emit(f"; end filament {k}")
        top = max(top, float(pts[:, 2].max()))
    assert w.xyz is not None
    w.rapid(np.array([*w.xyz[:2], _travel_height(m, top, w.xyz[2])]), "z")
    if layer_cure_s > 0:
        _cure(w, current_layer, layer_cure_s)
    if w.shift != 0.0:
        w.emit(f"G92 {m.rotary_axis}{_num(w.angle + w.shift)}")
    w.emit(*(m.end_lines or ()), *gcode_aerotech.subroutines(m), *m.footer_lines)
    order = "serpentine" if serpentine else "as designed"
    head = _header(
        m,
        len(printed),
        len(set(layers)),
        design_hash or programs_sha256(programs),
        w.time,
        order,
        turns,
        w,
        placeholders,
    )
    head = [*head[:3], *_materials_line(materials), *head[3:]]  # after the design's hash
    body = [*gcode_aerotech.declarations(m), *m.header_lines, *(m.setup_lines or ()), *w.lines]
    text = "\n".join([*head, *body]) + "\n"
    if re.search(r"[^\x20-\x7e\n]", text):  # pragma: no cover - every input is checked
        raise AssertionError("non-printable character in the program")
    for no, line in enumerate(text.splitlines(), 1):
        if len(line) > MAX_LINE:
            raise InvalidParameterError(
                "machine profile",
                f"line {no} of the program would be {len(line)} characters, over {MAX_LINE} "
                f"(LinuxCNC refuses lines over 252); shorten the profile's text: {line[:40]!r}...",
            )
    return text


def _start_word(w: _Writer, prog: PrintProgram, m: MachineProfile) -> float:
    """Rotary word of the filament's first vertex: the design angle + whole turns, near now."""
    first = float(prog.nozzle_angle[0]) * m.rotary_scale
    if m.rotary_rebase == "g92":
        here = w.angle - m.turn * round(w.angle / m.turn)  # what G92 re-bases to
    else:
        here = 0.0
    return float(np.round(first + m.turn * round((here - first) / m.turn), _DIGITS))


def _travel(w: _Writer, k: int, start: np.ndarray, zt: float, angle: float) -> None:
    """Lift, travel at ``zt``, re-base the rotary word, lower to ``start`` turning to ``angle``."""
    m = w.m
    if w.xyz is None:  # where the machine starts is unknown: go up first
        w.xyz = np.full(3, np.nan)
    w.rapid(np.array([w.xyz[0], w.xyz[1], zt]), "z")
    w.rapid(np.array([start[0], start[1], zt]), "xy")
    if m.rotary_rebase == "g92" and abs(w.angle) > m.turn / 2:
        rebased = float(np.round(w.angle - m.turn * round(w.angle / m.turn), _DIGITS))
        w.emit(f"G92 {m.rotary_axis}{_num(rebased)}")
        w.shift += w.angle - rebased
        w.angle = rebased
    drop = zt - float(start[2])
    turn = abs(angle - w.angle) / abs(m.rotary_scale)  # rad
    feed = m.travel_feed
    if turn * feed > m.max_rotation * drop:  # turning limits the lowering feed: 4 digits, down
        exact = m.max_rotation * drop / turn
        step = 10.0 ** (math.floor(math.log10(exact)) - 3)
        feed = math.floor(exact / step) * step
    if feed < m.min_feed:
        raise _limit(
            f"program {k}",
            f"unwinding {turn / (2 * math.pi):.1f} turns while lowering {drop:.3g} mm needs a "
            f"feed of {feed:.3g} mm/s, below the minimum",
            "rotary_rebase",
            "re-base instead (rotary_rebase = 'g92') or check",
        )
    w.linear(np.array(start, dtype=float), angle, feed, "z")


def _cure(w: _Writer, layer: int | None, seconds: float) -> None:
    """UV cure after a layer: lamp on, dwell, lamp off with the profile's lamp commands, else a
    real pause (the controller waits for the operator, who cures by hand and resumes)."""
    m = w.m
    if m.uv_on_template:
        w.emit(f"; UV cure after layer {layer}: {seconds:g} s", m.uv_on_template)
        w.dwell(seconds)
        if m.uv_off_template:
            w.emit(m.uv_off_template)
        return
    w.emit(
        f"; UV cure after layer {layer}: {seconds:g} s by hand (no lamp commands in the machine "
        f"profile): the program pauses ({m.pause_template}); switch the lamp on for "
        f"{seconds:g} s, off, then resume",
        m.pause_template or "",
    )
    w.time += seconds  # the operator's cure, counted in the estimate


def write_gcode(
    programs: Sequence[PrintProgram],
    path: str | FilePath,
    machine: MachineProfile,
    *,
    process: Process | Sequence[Process] | None = None,
    layer_cure_s: float = 0.0,
    design_hash: str | None = None,
    serpentine: bool = True,
    materials: MaterialSet | None = None,
) -> FilePath:
    """Write :func:`gcode_text` to ``path`` atomically and return the path.

    Nothing is written (not even a temporary file) if a limit is exceeded.
    """
    text = gcode_text(
        programs,
        machine,
        process=process,
        layer_cure_s=layer_cure_s,
        design_hash=design_hash,
        serpentine=serpentine,
        materials=materials,
    )
    return atomic_write_text(path, text)
