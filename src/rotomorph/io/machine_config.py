"""Controller-side configuration a rotomorph program needs, written beside it.

``rotomorph gcode DESIGN -o FILE --machine PROFILE --machine-config DIR`` writes, for the
profile's controller:

``linuxcnc``
    ``rotomorph.ini`` (the sections to merge into the machine's INI: a *non-wrapped* C axis whose
    limits cover the program's cumulative angle, the abort handler, units and kinematics; it is
    also a complete INI for LinuxCNC's standalone interpreter ``rs274``), ``rotomorph.hal``
    (the pressure outputs to wire), ``rotomorph_on_abort.ngc`` (every channel off on an abort),
    ``rotomorph.var`` and ``tool.tbl``.
``klipper``
    ``rotomorph.cfg`` (``[include]`` it from printer.cfg): the rotary ``manual_stepper``
    registered as G-code axis C, the two pressure ``output_pin`` sections, the
    ``ROTOMORPH_START`` / ``ROTOMORPH_END`` macros the program calls, and every channel off on a
    cancel, an error of a virtual-SD print, an idle timeout and an MCU shutdown.
``a3200``, ``marlin``, ``reprapfirmware``
    ``CONTROLLER-NOTES.txt``: what the operator must set up by hand, and why.

Pins, motor gearing and accelerations are the machine's and are marked ``SET_ME`` where the
profile cannot know them; docs/gcode.md says why each generated line is there.
"""

from __future__ import annotations

import math
import re
from pathlib import Path as FilePath

from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.gcode import pressure_lines
from rotomorph.io.machine import MachineProfile, fill_template

__all__ = ["ABORT_SUBROUTINE", "all_off_lines", "controller_files", "write_machine_config"]

#: Name of the LinuxCNC abort subroutine (file ``<name>.ngc`` on SUBROUTINE_PATH).
ABORT_SUBROUTINE = "rotomorph_on_abort"
_WOUND = re.compile(r"(?:winds up to|at most) ([\d.]+) turns")


def all_off_lines(m: MachineProfile) -> list[str]:
    """Lines that turn both channels off: valve closed and set-point 0 where there are both."""
    out = []
    for port in (m.active_port, m.passive_port):
        out += pressure_lines(m, port, 0.0, False)
        if m.pressure_idiom == "template" and m.valve_on_template and m.pressure_template:
            values = m.pressure_values(0.0)
            out.append(fill_template(m.pressure_template, port=port, **values))
    return out


def _wound_turns(program: str) -> float:
    """Largest physical winding (turns) the program's header states."""
    found = _WOUND.search(program)
    return float(found[1]) if found else 1.0


def _linuxcnc(m: MachineProfile, program: str) -> dict[str, str]:
    deg = 360.0 if m.rotary_units == "deg" else 2 * math.pi
    # the cumulative angle plus one turn of margin, rounded up to whole turns
    span = deg * (math.ceil(_wound_turns(program)) + 1)
    lo, hi = m.envelope_min, m.envelope_max
    linear = max(m.max_feed, m.travel_feed)
    rotary = m.max_rotation * abs(m.rotary_scale)
    unit = "degree" if m.rotary_units == "deg" else "radian"
    axes = {m.x_axis: (lo[0], hi[0]), m.y_axis: (lo[1], hi[1]), m.z_axis: (lo[2], hi[2])}
    coords = "".join([m.x_axis, m.y_axis, m.z_axis, m.rotary_axis])
    ini = [
        "# rotomorph: LinuxCNC settings for programs written for machine profile",
        f"# {m.name!r} ({m.source}); merge these sections into your machine's INI",
        "[RS274NGC]",
        "PARAMETER_FILE = rotomorph.var",
        "SUBROUTINE_PATH = .",
        "# every pressure channel off when a program is aborted (M64/M68 outputs keep their",
        "# values through an abort otherwise)",
        f"ON_ABORT_COMMAND = O <{ABORT_SUBROUTINE}> call",
        "",
        "[EMCIO]",
        "TOOL_TABLE = tool.tbl",
        "",
        "[TRAJ]",
        f"COORDINATES = {' '.join(coords)}",
        "LINEAR_UNITS = mm",
        f"ANGULAR_UNITS = {unit}",
        f"MAX_LINEAR_VELOCITY = {linear:g}",
        "",
        "[KINS]",
        f"KINEMATICS = trivkins coordinates={coords}",
        "JOINTS = 4",
    ]
    for letter, (a, b) in axes.items():
        ini += [
            "",
            f"[AXIS_{letter}]",
            f"MIN_LIMIT = {a:g}",
            f"MAX_LIMIT = {b:g}",
            f"MAX_VELOCITY = {linear:g}",
            "# SET_ME: the acceleration your axis can follow (LinuxCNC's INI reader keeps an",
            "# inline comment as part of the value, so comments stand on their own lines)",
            "MAX_ACCELERATION = 500",
        ]
    ini += [
        "",
        f"[AXIS_{m.rotary_axis}]",
        "# not WRAPPED_ROTARY: the program's rotary words are the cumulative nozzle angle (a",
        "# wrapped axis takes them modulo 360 and turns the long way); limits cover the largest",
        f"# winding of the program ({_wound_turns(program):g} turns) plus one turn",
        f"MIN_LIMIT = {-span:g}",
        f"MAX_LIMIT = {span:g}",
        f"MAX_VELOCITY = {rotary:.6g}",
        "# SET_ME: the acceleration your rotary stage can follow",
        "MAX_ACCELERATION = 20000",
    ]
    abort = [
        f"o<{ABORT_SUBROUTINE}> sub",
        "(rotomorph: every pressure channel off, run by ON_ABORT_COMMAND on any abort)",
        *all_off_lines(m),
        f"o<{ABORT_SUBROUTINE}> endsub",
        "M2",
    ]
    hal = [
        "# rotomorph: pressure outputs of the program (merge into your HAL file)",
        "# M64/M65 P<n> switch motion.digital-out-<n>; M68 E<n> Q<psi> sets motion.analog-out-<n>",
        "# (in psi: scale it to your regulator's input). The outputs must exist:",
        f"#   loadrt motmod ... num_dio={max(m.active_port, m.passive_port) + 1} "
        f"num_aio={max(m.active_port, m.passive_port) + 1}",
    ]
    for role in ("active", "passive"):
        port = getattr(m, f"{role}_port")
        hal += [
            f"net rotomorph-{role}-valve motion.digital-out-{port:02d} => SET_ME.{role}-valve",
            f"net rotomorph-{role}-psi motion.analog-out-{port:02d} => SET_ME.{role}-setpoint",
        ]
    return {
        "rotomorph.ini": "\n".join(ini) + "\n",
        f"{ABORT_SUBROUTINE}.ngc": "\n".join(abort) + "\n",
        "rotomorph.hal": "\n".join(hal) + "\n",
        "rotomorph.var": "",
        "tool.tbl": "T1 P1 D0 Z0 ;rotomorph: the nozzle (no tool offsets are used)\n",
    }


def _klipper(m: MachineProfile, program: str) -> dict[str, str]:
    rotary = math.degrees(m.max_rotation) if m.rotary_units == "deg" else m.max_rotation
    off = all_off_lines(m)
    pins = sorted(set(re.findall(r"PIN=(\w+)", "\n".join(off))))
    cfg = [
        "# rotomorph: Klipper sections for programs written for machine profile",
        f"# {m.name!r} ({m.source}); [include rotomorph.cfg] from printer.cfg",
        "# Needs Klipper 2025 or later (MANUAL_STEPPER ... GCODE_AXIS).",
        "",
        "[manual_stepper nozzle_rotation]",
        "# the rotary nozzle; its position is the program's C word in degrees",
        "step_pin: SET_ME",
        "dir_pin: SET_ME",
        "enable_pin: SET_ME",
        "microsteps: 16",
        "rotation_distance: 360  # SET_ME: degrees of the nozzle per motor turn (gearing)",
        f"velocity: {rotary:.6g}",
        "accel: 20000  # SET_ME: deg/s^2 your rotary stage can follow",
    ]
    for pin in pins:
        cfg += [
            "",
            f"[output_pin {pin}]",
            "pin: SET_ME",
            "pwm: True",
            "value: 0",
            "# off if the MCU shuts down (an error in the MCU or a lost connection)",
            "shutdown_value: 0",
        ]
    cfg += [
        "",
        "[pause_resume]",
        "",
        "[gcode_macro ROTOMORPH_ALL_OFF]",
        "description: every pressure channel off",
        "gcode:",
        *(f"  {line}" for line in off),
        "",
        "# the operator has turned the nozzle so that its active half faces +x: that is C 0",
        "[gcode_macro ROTOMORPH_START]",
        "description: called by the program: channels off, home, rotary as G-code axis C",
        "gcode:",
        "  ROTOMORPH_ALL_OFF",
        "  G28",
        "  MANUAL_STEPPER STEPPER=nozzle_rotation ENABLE=1",
        "  MANUAL_STEPPER STEPPER=nozzle_rotation SET_POSITION=0",
        f"  MANUAL_STEPPER STEPPER=nozzle_rotation GCODE_AXIS={m.rotary_axis} "
        f"LIMIT_VELOCITY={rotary:.6g}",
        "",
        "[gcode_macro ROTOMORPH_END]",
        "description: called at the end of the program: every channel off",
        "gcode:",
        "  ROTOMORPH_ALL_OFF",
        "",
        "[gcode_macro CANCEL_PRINT]",
        "description: every pressure channel off, then Klipper's own cancel",
        "rename_existing: BASE_CANCEL_PRINT",
        "gcode:",
        "  ROTOMORPH_ALL_OFF",
        "  BASE_CANCEL_PRINT",
        "",
        "[virtual_sdcard]",
        "path: ~/printer_data/gcodes  # SET_ME: where your host keeps programs",
        "# an error while printing from the virtual SD card (e.g. 'Move out of range') turns",
        "# every channel off before Klipper stops",
        "on_error_gcode:",
        "  ROTOMORPH_ALL_OFF",
        "",
        "[idle_timeout]",
        "gcode:",
        "  ROTOMORPH_ALL_OFF",
        "  M84",
    ]
    return {"rotomorph.cfg": "\n".join(cfg) + "\n"}


_NOTES = {
    "a3200": [
        "The program is self-contained: the DVAR line and the pressure subroutines (DFS blocks",
        "after M2) are in the file. Still to do by hand:",
        "- Check the COM ports (P) and the serial settings in the DFS blocks against your",
        "  regulators (115200 baud 8N1 written).",
        "- Make your controller's program-abort or task-stop handling run the lines below, so",
        "  an aborted program leaves no channel dispensing (the A3200 keeps serial regulators",
        "  at their last set-point):",
    ],
    "marlin": [
        "Marlin 2.1 with a rotary fourth axis: AXIS4_NAME 'C' and AXIS4_ROTATES in the firmware.",
        "- M42 drives the pressure pins: add them to your board's allowed M42 pins.",
        "- M0 (the UV-cure pause) needs a display or host that can resume (EMERGENCY_PARSER).",
        "- Marlin keeps M42 outputs on an abort: make your host's cancel G-code send the lines",
        "  below (e.g. OctoPrint's 'After print job is cancelled' script).",
    ],
    "reprapfirmware": [
        "RepRapFirmware 3 with a rotary axis C (M584 C.. R1 in config.g).",
        '- M42 P<n> needs the ports configured with M950 P<n> C"<pin>" Q<pwm frequency>.',
        "- Put the lines below in sys/cancel.g (run on a cancelled print) and make M226 (the",
        "  UV-cure pause) run them too in sys/pause.g if a pause may be left long.",
    ],
}


def controller_files(m: MachineProfile, program: str) -> dict[str, str]:
    """Files (name → text) the profile's controller needs for ``program`` (module docstring)."""
    if m.controller == "linuxcnc":
        return _linuxcnc(m, program)
    if m.controller == "klipper":
        return _klipper(m, program)
    lines = [
        f"rotomorph: controller set-up for machine profile {m.name!r} ({m.source})",
        "",
        *_NOTES[m.controller or "marlin"],
        "",
        *(f"    {line}" for line in all_off_lines(m)),
    ]
    return {"CONTROLLER-NOTES.txt": "\n".join(lines) + "\n"}


def write_machine_config(m: MachineProfile, program: str, folder: str | FilePath) -> list[FilePath]:
    """Write :func:`controller_files` into ``folder`` (created if missing), atomically each."""
    folder = FilePath(folder)
    folder.mkdir(parents=True, exist_ok=True)
    return [
        atomic_write_text(folder / name, text)
        for name, text in controller_files(m, program).items()
    ]
