"""Referee: LinuxCNC's own interpreter runs every LinuxCNC program the examples make.

``rs274`` (Debian package ``linuxcnc-uspace``) is LinuxCNC's standalone interpreter: it reads a
program as the controller does and prints the canonical machine calls (``STRAIGHT_FEED(x, y, z,
a, b, c)``, ``SET_FEED_RATE``, ``DWELL``, ``SET_AUX_OUTPUT_BIT``, …, 4 decimals). It runs here
with the INI that ``rotomorph gcode --machine-config`` generates for ``examples/machines/
linuxcnc.toml`` (non-wrapped C axis, abort handler). For every example design, a 6 × 6 dome
lattice and a design of arcs it must report 0 errors and 0 warnings, and its canonical output
must match the design: positions ≤ 1e-4 mm, the cumulative rotary ≤ 1e-3°, ω = dα/ds · v per
move to 2e-3 relative (the interpreter's 4 printed decimals), feeds, set-points, valves balanced
and off at the end, dwells; on the arcs, where the nozzle tracks the path, C is the arcs'
tangent minus the interface angle at every vertex, their ends included (≤ 1e-3°).
Then the same programs, aborted at several points and followed by the generated abort handler,
leave every channel off. What rs274 does not check: acceleration, blending and the real-time
motion (it plans nothing), and it accepts axis words outside the INI's COORDINATES.
"""

from __future__ import annotations

import re
import subprocess
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
from _gcode_cases import NAMES, ROOT, tangent_errors, written

from rotomorph.io.machine import load_machine_profile
from rotomorph.io.machine_config import ABORT_SUBROUTINE, controller_files

pytestmark = pytest.mark.referee

PROFILE = ROOT / "machines" / "linuxcnc.toml"
INSTALL = "apt-get install linuxcnc-uspace"
_CALL = re.compile(r"^\s*\d+ N\.\.\.\.\. (\w+)\((.*)\)\s*$")


def _run(rs274: str, folder: Path, program: str, ini_files: dict[str, str]) -> list[tuple]:
    for name, text in ini_files.items():
        (folder / name).write_text(text)
    (folder / "p.ngc").write_text(program)
    done = subprocess.run(
        [
            rs274,
            "-g",
            "-i",
            "rotomorph.ini",
            "-t",
            "tool.tbl",
            "-v",
            "rotomorph.var",
            "p.ngc",
            "out.canon",
        ],
        cwd=folder,
        capture_output=True,
        text=True,
        timeout=120,
    )
    noise = [ln for ln in (done.stdout + done.stderr).splitlines() if ln.strip() != "executing"]
    assert done.returncode == 0 and not noise, (done.returncode, noise[:5])
    calls = []
    for line in (folder / "out.canon").read_text().splitlines():
        hit = _CALL.match(line)
        assert hit, line
        calls.append((hit[1], hit[2]))
    assert not [c for c in calls if "WARN" in c[0] or "ERROR" in c[0] or "MESSAGE" in c[0]]
    return calls


def _numbers(args: str) -> list[float]:
    return [float(v) for v in re.split(r"[ ,]+", args.strip()) if v]


@pytest.fixture(scope="module")
def rs274(require_tool):
    return require_tool("rs274", INSTALL)


@pytest.mark.parametrize("name", [*NAMES, "arcs"])
def test_rs274_runs_every_program_as_designed(rs274, tmp_path, name):
    m = load_machine_profile(PROFILE)
    text, printed, process = written(name, PROFILE)
    calls = _run(rs274, tmp_path, text, controller_files(m, text))
    # walk the canonical calls: outputs, feeds and the feed moves with outputs on
    valve = {m.active_port: False, m.passive_port: False}
    setpoint: dict[int, float] = {}
    feed = None
    pos = None
    filaments: list[dict] = []
    current = None
    dwells = []
    for call, args in calls:
        if call in ("SET_AUX_OUTPUT_BIT", "CLEAR_AUX_OUTPUT_BIT"):
            valve[int(args)] = call.startswith("SET")
        elif call == "SET_AUX_OUTPUT_VALUE":
            port, value = _numbers(args)
            setpoint[int(port)] = value
        elif call == "SET_FEED_RATE":
            feed = _numbers(args)[0] / 60.0
        elif call == "DWELL":
            dwells.append(_numbers(args)[0])
        elif call in ("STRAIGHT_FEED", "STRAIGHT_TRAVERSE"):
            x, y, z, _a, _b, c = _numbers(args)[:6]
            on = any(valve.values())
            if call == "STRAIGHT_TRAVERSE":
                assert not on, "a rapid move with a channel open"
            if on:
                if current is None:
                    current = {
                        "pts": [pos[:3]],
                        "c": [pos[3]],
                        "feed": [],
                        "on": dict(valve),
                        "psi": dict(setpoint),
                    }
                    filaments.append(current)
                current["pts"].append((x, y, z))
                current["c"].append(c)
                current["feed"].append(feed)
            pos = (x, y, z, c)
        if not any(valve.values()):
            current = None
    assert not any(valve.values()), "a valve open at the end"
    assert len(filaments) == len(printed)
    for got, prog, proc in zip(filaments, printed, process, strict=True):
        pts = np.array(got["pts"])
        assert np.max(np.abs(pts - prog.points)) <= 1e-4 + 5e-5  # design vs 4-decimal print
        c = np.array(got["c"])
        design = np.degrees(prog.nozzle_angle)
        design = design + 360.0 * np.round((c[0] - design[0]) / 360.0)  # whole turns of re-basing
        assert np.max(np.abs(c - design)) <= 1e-3
        feeds = np.array(got["feed"])
        np.testing.assert_allclose(feeds, prog.speed[:-1], rtol=1e-6, atol=1e-4 / 60)
        ds = np.linalg.norm(np.diff(pts, axis=0), axis=1)
        omega = np.radians(np.diff(c)) / ds * feeds
        want = np.diff(prog.nozzle_angle) / prog.path.edge_lengths * prog.speed[:-1]
        # 4 printed decimals of C and of the positions bound the error of each move's rate
        bound = 2e-3 * np.abs(want) + np.radians(1e-4) / ds * feeds + np.abs(want) * 1e-4 / ds
        assert np.all(np.abs(omega - want) <= bound)
        channels = dict(proc.channels(prog.active_fraction))
        ports = {getattr(m, f"{role}_port"): psi for role, psi in channels.items()}
        assert {p for p, o in got["on"].items() if o} == set(ports)
        assert all(abs(got["psi"][p] - psi) <= 1e-4 for p, psi in ports.items())
    for proc in process:
        for wanted in (proc.prime_dwell, proc.release_dwell):
            assert wanted == 0 or any(abs(d - wanted) < 1e-4 for d in dwells)
    if name == "arcs":  # C as the interpreter reads it: the arcs' tangent − α, to their ends
        read = [
            SimpleNamespace(points=np.array(f["pts"]), nozzle_angle=np.radians(f["c"]))
            for f in filaments
        ]
        off = tangent_errors(read)
        assert len(off) == 3 and max(np.max(np.abs(o)) for o in off) <= 1e-3, off


@pytest.mark.parametrize("name", ["composite_rotation", "lattice_dome_6x6"])
def test_an_aborted_program_leaves_every_channel_off(rs274, tmp_path, name):
    """The program cut at several points (mid-filament included), then the abort handler the
    generated INI names in ON_ABORT_COMMAND, run by rs274 with that INI."""
    m = load_machine_profile(PROFILE)
    text = written(name, PROFILE)[0]
    files = controller_files(m, text)
    ini = files["rotomorph.ini"]
    assert f"ON_ABORT_COMMAND = O <{ABORT_SUBROUTINE}> call" in ini
    assert "WRAPPED_ROTARY" not in ini.replace("not WRAPPED_ROTARY", "")
    lines = text.splitlines()
    end = max(i for i, ln in enumerate(lines) if ln == "M2")
    opened = [i for i, ln in enumerate(lines) if ln.startswith("M64")]
    cuts = sorted({opened[0] + 3, opened[len(opened) // 2] + 10, end - 5})
    for k, cut in enumerate(cuts):
        folder = tmp_path / f"cut{k}"
        folder.mkdir()
        program = "\n".join([*lines[:cut], f"O <{ABORT_SUBROUTINE}> call", "M2"]) + "\n"
        calls = _run(rs274, folder, program, files)
        valve = {}
        value = {}
        for call, args in calls:
            if call in ("SET_AUX_OUTPUT_BIT", "CLEAR_AUX_OUTPUT_BIT"):
                valve[int(args)] = call.startswith("SET")
            elif call == "SET_AUX_OUTPUT_VALUE":
                port, v = _numbers(args)
                value[int(port)] = v
        before = [ln for ln in lines[:cut] if ln.startswith(("M64", "M65"))]
        was_on = {int(ln[5:]) for ln in before if ln.startswith("M64")} - {
            int(ln[5:]) for ln in before[len(before) - 1 :] if ln.startswith("M65")
        }
        if k < 2:  # the cuts inside a filament: a channel was dispensing when it was aborted
            assert before[-1].startswith("M64") and was_on
        assert valve == {m.active_port: False, m.passive_port: False}
        assert value == {m.active_port: 0.0, m.passive_port: 0.0}


def test_every_ini_value_reads_back_as_written_by_linuxcncs_own_ini_reader(require_tool, tmp_path):
    """LinuxCNC's INI reader (``inivar``, the same reader the controller uses) keeps an inline
    comment as part of a value (``500  # note`` reads as that whole string), so every value
    the generated INI holds must read back exactly as the bare value: numbers as numbers."""
    inivar = require_tool("inivar", INSTALL)
    m = load_machine_profile(PROFILE)
    text, _, _ = written(NAMES[0], PROFILE)
    ini = controller_files(m, text)["rotomorph.ini"]
    (tmp_path / "rotomorph.ini").write_text(ini)
    section, checked = "", 0
    for line in ini.splitlines():
        stripped = line.strip()
        if not stripped or stripped[0] in "#;":
            continue
        if stripped.startswith("["):
            section = stripped.strip("[]")
            continue
        key, value = (part.strip() for part in stripped.split("=", 1))
        got = subprocess.run(
            [inivar, "-var", key, "-sec", section, "-ini", "rotomorph.ini"],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=30,
        )
        assert got.returncode == 0, (section, key, got.stderr)
        assert got.stdout.strip() == value, (section, key, got.stdout)
        assert "#" not in value and ";" not in value, (section, key, value)
        if key.endswith(("LIMIT", "VELOCITY", "ACCELERATION")):
            float(value)
        checked += 1
    assert checked >= 20
