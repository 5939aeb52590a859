"""G-code writer for rotational multimaterial printing (DESIGN.md section 7).

Layout of the emitted program (one block per filament, layers in order)::

    ; header: tool version, design sha256, dialect, units, axis mapping, estimated time
    G71 / G76 / G90           (aerotech)      or   G21 / G90 (rs274, marlin)
    ; layer 0
    ; filament 0 layer=0 radius=0.3 active_fraction=0.5 active_material=lce passive_material=...
    G0 Z<z+lift>              lift (pressures are off)
    G0 X.. Y.. A..            travel to the start, turning the nozzle to its start angle
    G0 Z<z>                   lower
    <pressure active on>      explicit set-points, never toggles
    <pressure passive on>
    G1 X.. Y.. [Z..] A.. F..  one print move per edge: rotary axis in the same block,
    ...                       cumulative (unwrapped) angle, so dα_n/ds = ω/v on every move
    <pressure active 0>       explicit off
    <pressure passive 0>
    ; end filament 0
    [; UV cure after layer 0: dwell] (optional)
    M2

The move that leaves vertex i runs at ``speed[i]`` (``PrintProgram`` convention). The writer
refuses, before writing anything, a program that leaves the envelope or exceeds the feed,
rotation or pressure limits (:class:`~rotomorph.errors.MachineLimitError`).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path as FilePath

import numpy as np

import rotomorph
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError, MachineLimitError, MaterialError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.machine import MachineProfile, check_line
from rotomorph.materials.material import get_material, known_materials

__all__ = ["check_materials", "gcode_text", "programs_sha256", "write_gcode"]

Pressure = tuple[float, float]
_EPS = 1e-9
_DIGITS = 6  # decimals of position and angle words (mm, deg or rad)


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


def _num(x: float, digits: int = 6) -> str:
    """``x`` with at most ``digits`` decimals, trailing zeros dropped, never ``-0``."""
    s = f"{x:.{digits}f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _feed(x: float) -> str:
    """A feed word's number: 10 significant digits, positional (never ``0``, never ``1e-05``)."""
    return np.format_float_positional(x, precision=10, unique=True, fractional=False, trim="-")


def check_materials(programs: Sequence[PrintProgram]) -> None:
    """Every material a program names must be registered and be one printable word.

    The same check as ``rotomorph validate`` (``get_material``), plus the text check of
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
                get_material(name)
            except MaterialError:
                raise MaterialError(
                    f"print program {i}: {role} material",
                    f"unknown material {name!r}; known: {', '.join(known_materials())}",
                ) from None


def _pressures(pressures: Pressure | Sequence[Pressure], n: int) -> list[Pressure]:
    arr = np.asarray(pressures, dtype=float)
    if arr.shape == (2,):
        arr = np.broadcast_to(arr, (n, 2))
    if arr.shape != (n, 2):
        raise InvalidParameterError(
            "pressures",
            f"must be (active, passive) psi or one pair per program ({n}); got shape {arr.shape}",
        )
    return [(float(a), float(p)) for a, p in arr]


@dataclass(frozen=True)
class _Written:
    """One filament as it is written: rounded positions, angle words and feeds."""

    points: np.ndarray  # (N, 3) mm, rounded to the written decimals
    angle: np.ndarray  # (N,) rotary words (deg or rad, with the profile's sign)
    feed: np.ndarray  # (N-1,) mm/s of the move that leaves vertex i
    rotation: np.ndarray  # (N-1,) rad/s of each move, from the written numbers


def _written(prog: PrintProgram, m: MachineProfile, start_angle: float) -> _Written:
    """Round positions to :data:`_DIGITS`; carry the design's dα/ds onto the written lengths.

    The angle increments are rate × written length, so dα/ds · v = ω holds per move for the
    numbers in the file (to the angle word's rounding), not only for the design's floats.
    """
    pts = np.round(prog.points, _DIGITS)
    ds_design = prog.path.edge_lengths
    ds_written = np.linalg.norm(np.diff(pts, axis=0), axis=1)
    if np.any(ds_written <= 0):
        i = int(np.flatnonzero(ds_written <= 0)[0])
        raise InvalidParameterError(
            "programs", f"move {i} is shorter than the written resolution 1e-{_DIGITS} mm"
        )
    rate = np.diff(prog.nozzle_angle) / ds_design  # rad/mm
    angle = start_angle + np.concatenate([[0.0], np.cumsum(rate * ds_written)])
    word = np.round(angle * m.rotary_scale, _DIGITS)
    feed = prog.speed[:-1]
    rotation = np.abs(np.diff(word) / m.rotary_scale) / ds_written * feed
    return _Written(pts, word, feed, rotation)


def _limit(k: int, what: str, key: str, hint: str) -> MachineLimitError:
    return MachineLimitError(f"program {k}: {what}; {hint} (machine profile key '{key}')")


def _check_program(
    k: int, prog: PrintProgram, w: _Written, pr: Pressure, m: MachineProfile
) -> None:
    lo, hi = np.array(m.envelope_min), np.array(m.envelope_max)
    out = np.flatnonzero(((w.points < lo - _EPS) | (w.points > hi + _EPS)).any(axis=1))
    if out.size:
        i = int(out[0])
        side = "envelope_max" if (w.points[i] > hi + _EPS).any() else "envelope_min"
        raise _limit(
            k,
            f"vertex {i} at {np.round(w.points[i], 4).tolist()} mm leaves the envelope "
            f"{list(m.envelope_min)}..{list(m.envelope_max)} mm of machine {m.name!r}",
            side,
            "translate the design or change",
        )
    fast = np.flatnonzero(w.feed > m.max_feed * (1 + 1e-12))
    if fast.size:
        i = int(fast[0])
        raise _limit(
            k,
            f"speed {w.feed[i]:g} mm/s at vertex {i} exceeds the maximum feed {m.max_feed:g} mm/s",
            "max_feed",
            "slow the design or raise",
        )
    slow = np.flatnonzero(w.feed < m.min_feed * (1 - 1e-12))
    if slow.size:
        i = int(slow[0])
        raise _limit(
            k,
            f"speed {w.feed[i]:g} mm/s at vertex {i} is below the minimum feed {m.min_feed:g} mm/s",
            "min_feed",
            "speed the design up or lower",
        )
    spin = np.flatnonzero(w.rotation > m.max_rotation * (1 + 1e-9))
    if spin.size:
        i = int(spin[0])
        raise _limit(
            k,
            f"nozzle rotation {w.rotation[i]:.4g} rad/s on the move from vertex {i} exceeds "
            f"the maximum {m.max_rotation:.4g} rad/s",
            "max_rotation",
            "slow down, spread the flip (flip_length) or raise",
        )
    for name, value in zip(("active", "passive"), pr, strict=True):
        if not (math.isfinite(value) and m.min_pressure <= value <= m.max_pressure):
            raise _limit(
                k,
                f"{name} pressure {value:g} psi outside [{m.min_pressure:g}, "
                f"{m.max_pressure:g}] psi",
                "max_pressure" if value > m.min_pressure else "min_pressure",
                "change the design's pressure or",
            )
    if max(pr) <= 0:
        raise InvalidParameterError(
            "pressures", f"program {k}: both pressures are 0 psi; nothing would be extruded"
        )


def _pressure_line(machine: MachineProfile, port: int, psi: float) -> str:
    if machine.dialect == "aerotech":
        return f"Call setAlicatPress P{port} Q{_num(psi, 3)}"
    return machine.pressure_template.format(port=port, psi=psi)


def _dwell(machine: MachineProfile, seconds: float) -> str:
    return f"G4 S{_num(seconds, 3)}" if machine.dialect == "marlin" else f"G4 P{_num(seconds, 3)}"


def _travel_heights(programs: Sequence[PrintProgram], m: MachineProfile) -> list[float]:
    """Travel height before each program and after the last (mm).

    The nozzle lifts ``lift`` above the highest point printed so far (and above the start and
    end of the travel), so a travel never crosses the part however high a filament climbed.
    """
    heights = []
    top = -math.inf
    here_z = -math.inf
    for prog in programs:
        pts = np.round(prog.points, _DIGITS)
        heights.append(max(top, here_z, pts[0, 2]) + m.lift)
        top = max(top, float(pts[:, 2].max()))
        here_z = float(pts[-1, 2])
    heights.append(max(top, here_z) + m.lift)
    for k, z in enumerate(heights):
        if z > m.envelope_max[2] + _EPS:
            where = f"before program {k}" if k < len(programs) else "after the last program"
            raise MachineLimitError(
                f"travel height {z:.4g} mm {where} (lift {m.lift:g} mm above the highest point "
                f"printed) exceeds the envelope's z maximum {m.envelope_max[2]:g} mm; lower "
                "'lift' or raise 'envelope_max' in the machine profile"
            )
    return heights


def _estimate_time(
    programs: Sequence[PrintProgram], heights: list[float], m: MachineProfile, cure_s: float
) -> float:
    t = 0.0
    here = None
    for p, zt in zip(programs, heights, strict=False):
        if here is not None:
            flat = float(np.linalg.norm(p.points[0, :2] - here[:2]))
            t += (flat + (zt - here[2]) + (zt - p.points[0, 2])) / m.travel_feed
        t += p.duration
        here = p.points[-1]
    layers = sorted({p.layer for p in programs})
    return t + cure_s * len(layers)


def _machine_lines(m: MachineProfile) -> list[str]:
    if m.is_builtin:
        origin = (
            "built-in default (no machine profile given: its envelope and limits are "
            "assumptions; pass --machine FILE for your printer)"
        )
    else:
        origin = f"profile {m.source}"
    return [
        f"; machine: {m.name}, {origin}",
        f"; limits: envelope {list(m.envelope_min)}..{list(m.envelope_max)} mm, feed "
        f"{m.min_feed:g}..{m.max_feed:g} mm/s, rotation <= {m.max_rotation:g} rad/s, pressure "
        f"{m.min_pressure:g}..{m.max_pressure:g} psi, travel lift {m.lift:g} mm",
    ]


def gcode_text(
    programs: Sequence[PrintProgram],
    machine: MachineProfile,
    *,
    pressures: Pressure | Sequence[Pressure] = (30.0, 30.0),
    layer_cure_s: float = 0.0,
    design_hash: str | None = None,
) -> str:
    """G-code for ``programs`` on ``machine`` (pure; see module docstring for the layout).

    Parameters
    ----------
    programs
        Filaments in print order; layers must not decrease.
    machine
        The printer (required): limits, axes, dialect, pressure ports.
    pressures
        (active, passive) set-points in psi, one pair for all or one per program.
    layer_cure_s
        UV-cure dwell after each layer (s); 0 writes none (paper: cure after each layer).
    design_hash
        sha256 to record in the header; default :func:`programs_sha256` of ``programs``.

    Raises
    ------
    MachineLimitError
        Envelope (travel included), feed (minimum and maximum), rotation or pressure limit
        exceeded; the message names the machine-profile key (nothing is produced).
    MaterialError
        A material that ``rotomorph validate`` would refuse.
    InvalidParameterError
        No programs, decreasing layers, bad pressures or cure time, a name that is not one word
        of printable ASCII.
    """
    if len(programs) == 0:
        raise InvalidParameterError("programs", "needs at least one PrintProgram")
    layers = [p.layer for p in programs]
    if any(b < a for a, b in itertools.pairwise(layers)):
        raise InvalidParameterError("programs", "must be ordered by layer (non-decreasing)")
    if not (math.isfinite(layer_cure_s) and layer_cure_s >= 0):
        raise InvalidParameterError("layer_cure_s", f"must be >= 0 s; got {layer_cure_s}")
    if design_hash is not None and not re.fullmatch(r"[0-9a-f]{64}", design_hash):
        raise InvalidParameterError("design_hash", "must be a sha256 hex digest (64 characters)")
    check_materials(programs)
    press = _pressures(pressures, len(programs))
    m = machine
    written = [_written(p, m, float(p.nozzle_angle[0])) for p in programs]
    for k, (prog, w, pr) in enumerate(zip(programs, written, press, strict=True)):
        _check_program(k, prog, w, pr, m)
    heights = _travel_heights(programs, m)
    X, Y, Z, A = m.x_axis, m.y_axis, m.z_axis, m.rotary_axis
    f_unit = "mm/s" if m.dialect == "aerotech" else "mm/min"
    total = _estimate_time(programs, heights, m, layer_cure_s)
    out = [
        "; rotomorph G-code (rotational multimaterial printing)",
        f"; tool: rotomorph {rotomorph.__version__}",
        f"; design-sha256: {design_hash or programs_sha256(programs)}",
        *_machine_lines(m),
        f"; dialect: {m.dialect}",
        f"; units: length mm, feed {f_unit}, rotary {m.rotary_units}, pressure psi",
        f"; axes: {X}=x {Y}=y {Z}=z {A}=nozzle angle (sign {m.rotary_sign:+d}, ccw from +x seen "
        "from above), cumulative",
        f"; pressure channels: active port {m.active_port}, passive port {m.passive_port}",
        f"; filaments: {len(programs)}, layers: {len(set(layers))}",
        f"; estimated print time: {total:.1f} s",
    ]
    out += ["G71", "G76", "G90"] if m.dialect == "aerotech" else ["G21", "G90"]
    fs = m.feed_scale
    current_layer = None
    for k, (prog, w, (pa, pp)) in enumerate(zip(programs, written, press, strict=True)):
        if prog.layer != current_layer:
            if current_layer is not None and layer_cure_s > 0:
                out += _cure(m, current_layer, layer_cure_s)
            current_layer = prog.layer
            out.append(f"; layer {prog.layer}")
        pts, ang = w.points, w.angle
        out.append(
            f"; filament {k} layer={prog.layer} radius={prog.radius!r} "
            f"active_fraction={prog.active_fraction!r} active_material={prog.active_material} "
            f"passive_material={prog.passive_material}"
        )
        x0, y0, z0 = pts[0]
        out += [
            f"G0 {Z}{_num(heights[k])}",
            f"G0 {X}{_num(x0)} {Y}{_num(y0)} {A}{_num(ang[0])}",
            f"G0 {Z}{_num(z0)}",
            _pressure_line(m, m.active_port, pa),
            _pressure_line(m, m.passive_port, pp),
        ]
        zc = z0
        for i in range(1, len(pts)):
            x, y, z = pts[i]
            zword = f" {Z}{_num(z)}" if _num(z) != _num(zc) else ""
            zc = z
            out.append(
                f"G1 {X}{_num(x)} {Y}{_num(y)}{zword} {A}{_num(ang[i])} "
                f"F{_feed(w.feed[i - 1] * fs)}"
            )
        out += [
            _pressure_line(m, m.active_port, 0.0),
            _pressure_line(m, m.passive_port, 0.0),
            f"; end filament {k}",
        ]
    if layer_cure_s > 0:
        out += _cure(m, current_layer, layer_cure_s)
    out.append(f"G0 {Z}{_num(heights[-1])}")
    if m.dialect != "marlin":
        out.append("M2")
    text = "\n".join(out) + "\n"
    assert all(32 <= ord(c) < 127 for c in text.replace("\n", ""))
    return text


def _cure(m: MachineProfile, layer: int | None, seconds: float) -> list[str]:
    lines = [f"; UV cure after layer {layer}: {seconds:g} s"]
    lines += [m.uv_on_template] if m.uv_on_template else []
    lines.append(_dwell(m, seconds))
    lines += [m.uv_off_template] if m.uv_off_template else []
    return lines


def write_gcode(
    programs: Sequence[PrintProgram],
    path: str | FilePath,
    machine: MachineProfile,
    *,
    pressures: Pressure | Sequence[Pressure] = (30.0, 30.0),
    layer_cure_s: float = 0.0,
    design_hash: str | None = None,
) -> FilePath:
    """Write :func:`gcode_text` to ``path`` atomically and return the path.

    Nothing is written (not even a temporary file) if a limit is exceeded.
    """
    text = gcode_text(
        programs, machine, pressures=pressures, layer_cure_s=layer_cure_s, design_hash=design_hash
    )
    return atomic_write_text(path, text)
