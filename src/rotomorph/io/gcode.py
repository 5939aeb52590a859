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
from collections.abc import Sequence
from pathlib import Path as FilePath

import numpy as np

import rotomorph
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError, MachineLimitError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.machine import MachineProfile

__all__ = ["gcode_text", "programs_sha256", "write_gcode"]

Pressure = tuple[float, float]
_EPS = 1e-9


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


def _num(x: float, digits: int = 4) -> str:
    s = f"{x:.{digits}f}"
    return "0." + "0" * digits if s.lstrip("-").strip("0.") == "" else s


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


def _check_limits(
    programs: Sequence[PrintProgram], pressures: list[Pressure], machine: MachineProfile
) -> None:
    lo, hi = np.array(machine.envelope_min), np.array(machine.envelope_max)
    for k, (prog, pr) in enumerate(zip(programs, pressures, strict=False)):
        pts = prog.points
        lifted = pts[[0, -1]] + [0.0, 0.0, machine.lift]
        for label, arr in (("vertex", pts), ("travel height of vertex", lifted)):
            out = np.flatnonzero(((arr < lo - _EPS) | (arr > hi + _EPS)).any(axis=1))
            if out.size:
                i = int(out[0])
                raise MachineLimitError(
                    f"program {k}: {label} {i} at {np.round(arr[i], 4).tolist()} mm leaves the "
                    f"envelope {lo.tolist()}..{hi.tolist()} of machine {machine.name!r}; "
                    "translate the design or enlarge MachineProfile.envelope_*"
                )
        fast = np.flatnonzero(prog.speed[:-1] > machine.max_feed + _EPS)
        if fast.size:
            i = int(fast[0])
            raise MachineLimitError(
                f"program {k}: speed {prog.speed[i]:g} mm/s at vertex {i} exceeds max_feed "
                f"{machine.max_feed:g} mm/s"
            )
        rate = np.abs(np.diff(prog.nozzle_angle)) * prog.speed[:-1] / prog.path.edge_lengths
        spin = np.flatnonzero(rate > machine.max_rotation * (1 + 1e-9))
        if spin.size:
            i = int(spin[0])
            raise MachineLimitError(
                f"program {k}: nozzle rotation {rate[i]:.4g} rad/s on the move from vertex {i} "
                f"exceeds max_rotation {machine.max_rotation:.4g} rad/s; slow down or smooth α_n"
            )
        for name, value in zip(("active", "passive"), pr, strict=False):
            if not (machine.min_pressure <= value <= machine.max_pressure):
                raise MachineLimitError(
                    f"program {k}: {name} pressure {value:g} psi outside "
                    f"[{machine.min_pressure:g}, {machine.max_pressure:g}] psi"
                )


def _pressure_line(machine: MachineProfile, port: int, psi: float) -> str:
    if machine.dialect == "aerotech":
        return f"Call setAlicatPress P{port} Q{_num(psi, 3)}"
    return machine.pressure_template.format(port=port, psi=psi)


def _dwell(machine: MachineProfile, seconds: float) -> str:
    return f"G4 S{_num(seconds, 3)}" if machine.dialect == "marlin" else f"G4 P{_num(seconds, 3)}"


def _estimate_time(
    programs: Sequence[PrintProgram], machine: MachineProfile, cure_s: float
) -> float:
    t = 0.0
    here = None
    for p in programs:
        if here is not None:
            t += (
                float(np.linalg.norm(p.points[0] - here)) + 2 * machine.lift
            ) / machine.travel_feed
        t += p.duration
        here = p.points[-1]
    layers = sorted({p.layer for p in programs})
    return t + cure_s * len(layers)


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
        Envelope, feed, rotation or pressure limit exceeded (nothing is produced).
    InvalidParameterError
        No programs, decreasing layers, bad pressures or cure time.
    """
    if len(programs) == 0:
        raise InvalidParameterError("programs", "needs at least one PrintProgram")
    layers = [p.layer for p in programs]
    if any(b < a for a, b in itertools.pairwise(layers)):
        raise InvalidParameterError("programs", "must be ordered by layer (non-decreasing)")
    if not (math.isfinite(layer_cure_s) and layer_cure_s >= 0):
        raise InvalidParameterError("layer_cure_s", f"must be >= 0 s; got {layer_cure_s}")
    press = _pressures(pressures, len(programs))
    _check_limits(programs, press, machine)
    m = machine
    X, Y, Z, A = m.x_axis, m.y_axis, m.z_axis, m.rotary_axis
    f_unit = "mm/s" if m.dialect == "aerotech" else "mm/min"
    total = _estimate_time(programs, m, layer_cure_s)
    out = [
        "; rotomorph G-code (rotational multimaterial printing)",
        f"; tool: rotomorph {rotomorph.__version__}",
        f"; design-sha256: {design_hash or programs_sha256(programs)}",
        f"; machine: {m.name}",
        f"; dialect: {m.dialect}",
        f"; units: length mm, feed {f_unit}, rotary {m.rotary_units}, pressure psi",
        f"; axes: {X}=x {Y}=y {Z}=z {A}=nozzle angle (sign {m.rotary_sign:+d}, ccw from +x seen "
        "from above), cumulative",
        f"; pressure channels: active port {m.active_port}, passive port {m.passive_port}",
        f"; filaments: {len(programs)}, layers: {len(set(layers))}",
        f"; estimated print time: {total:.1f} s",
    ]
    out += ["G71", "G76", "G90"] if m.dialect == "aerotech" else ["G21", "G90"]
    fs, rs = m.feed_scale, m.rotary_scale
    current_layer = None
    for k, (prog, (pa, pp)) in enumerate(zip(programs, press, strict=False)):
        if prog.layer != current_layer:
            if current_layer is not None and layer_cure_s > 0:
                out += _cure(m, current_layer, layer_cure_s)
            current_layer = prog.layer
            out.append(f"; layer {prog.layer}")
        pts, ang = prog.points, prog.nozzle_angle * rs
        out.append(
            f"; filament {k} layer={prog.layer} radius={prog.radius!r} "
            f"active_fraction={prog.active_fraction!r} active_material={prog.active_material} "
            f"passive_material={prog.passive_material}"
        )
        x0, y0, z0 = pts[0]
        out += [
            f"G0 {Z}{_num(z0 + m.lift)}",
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
                f"F{_num(prog.speed[i - 1] * fs)}"
            )
        out += [
            _pressure_line(m, m.active_port, 0.0),
            _pressure_line(m, m.passive_port, 0.0),
            f"; end filament {k}",
        ]
    if layer_cure_s > 0:
        out += _cure(m, current_layer, layer_cure_s)
    out.append(f"G0 {Z}{_num(min(programs[-1].points[-1, 2] + m.lift, m.envelope_max[2]))}")
    if m.dialect != "marlin":
        out.append("M2")
    return "\n".join(out) + "\n"


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
