"""Static checks of every dialect against its controller's documented command set (no
interpreter of Marlin, RepRapFirmware or the Aerotech A3200 installs here).

- every line of every program of every example profile is at most 250 characters (LinuxCNC
  refuses lines over 252);
- Aerotech: every ``Call`` has its ``DFS`` in the same file, every user variable of the
  subroutines is declared by the ``DVAR`` line, travel is ``G1`` at ``travel_feed`` (an A3200
  ``G0`` runs at the controller's rapid rate), velocity blending is on, and at every filament end
  the C word is the design's angle there (to 1e-3°);
- Marlin, Klipper, RepRapFirmware: every command is one the firmware documents, and every axis
  word is one its ``G0``/``G1``/``G92`` accept (Klipper's ``G92``: X, Y, Z, E only — so no
  ``G92`` with a rotary word in a Klipper program);
- pressure commands set explicit states: no Nordson toggle is ever written;
- on a design of arcs, in every dialect, C at every vertex where the nozzle tracks the path is
  the arcs' tangent minus the interface angle, their ends included (the tangent from the arcs'
  centres, computed in the test).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from _gcode_cases import DESIGNS, PROFILES, ROOT, case, tangent_errors, written

from rotomorph.io.designfile import load_design
from rotomorph.io.gcode import MAX_LINE, gcode_text
from rotomorph.io.gcode_aerotech import undefined_calls
from rotomorph.io.gcode_read import parse_gcode
from rotomorph.io.machine import load_machine_profile

#: A3200 AeroBasic built-ins the subroutines use besides the declared variables.
AEROBASIC_BUILTINS = {"$P", "$Q", "$global"}
#: Commands each firmware documents, as the writer may use them (G-code words and macros).
FIRMWARE = {
    "marlin": {"G0", "G1", "G4", "G21", "G90", "G92", "M0", "M42"},
    "reprapfirmware": {"G0", "G1", "G4", "G21", "G90", "G92", "M226", "M42"},
    "klipper": {
        "G0",
        "G1",
        "G4",
        "G21",
        "G90",
        "PAUSE",
        "SET_PIN",
        "ROTOMORPH_START",
        "ROTOMORPH_END",
    },
}
#: Axis words each firmware's G0/G1 and G92 accept (Marlin: AXIS4_NAME; RRF: any configured
#: axis letter; Klipper: X Y Z E and registered extra axes for G0/G1, X Y Z E for G92).
MOVE_AXES = {
    "marlin": set("XYZABCUVW"),
    "reprapfirmware": set("XYZUVWABCD"),
    "klipper": set("XYZEC"),
}
G92_AXES = {
    "marlin": set("XYZABCUVWE"),
    "reprapfirmware": set("XYZUVWABCDE"),
    "klipper": set("XYZE"),
}


def _program(design: Path, profile: Path) -> str:
    return written(design.stem, profile)[0]


@pytest.mark.parametrize("profile", PROFILES, ids=lambda p: p.stem)
@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_every_line_of_every_dialect_is_short(design, profile):
    text = _program(design, profile)
    assert max(len(line) for line in text.splitlines()) <= MAX_LINE
    assert "togglePress" not in text  # explicit pressure states only


def test_a_long_profile_line_is_refused():
    from rotomorph.errors import InvalidParameterError
    from rotomorph.io.machine import MachineProfile

    d = load_design(ROOT / "designs" / "sinusoids.toml")
    long = MachineProfile(name="x" * 240)
    with pytest.raises(InvalidParameterError, match="over 250"):
        gcode_text(d.to_programs(), long)


AEROTECH = [p for p in PROFILES if p.stem.startswith("aerotech")]


@pytest.mark.parametrize("profile", AEROTECH, ids=lambda p: p.stem)
@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_aerotech_programs_are_self_contained(design, profile):
    m = load_machine_profile(profile)
    text = _program(design, profile)
    assert undefined_calls(text) == []
    lines = text.splitlines()
    calls = [ln for ln in lines if ln.startswith("Call ")]
    assert calls, "the pressure calls are written"
    dvar = [ln for ln in lines if ln.startswith("DVAR ")]
    assert len(dvar) == 1 and lines.index(dvar[0]) < lines.index("G71")
    declared = set(dvar[0].split()[1:])
    body = "\n".join(lines[lines.index("M2") :])
    used = set(re.findall(r"\$[A-Za-z]\w*", body))
    assert used <= declared | AEROBASIC_BUILTINS, used - declared - AEROBASIC_BUILTINS
    # every DFS closed, none nested
    depth = 0
    for line in lines:
        if line.startswith("DFS "):
            assert depth == 0
            depth = 1
        elif line == "ENDDFS":
            assert depth == 1
            depth = 0
    assert depth == 0
    assert "VELOCITY ON" in lines[: lines.index("M2")]
    assert not any(ln.startswith("G0") for ln in lines)  # travel is G1 at travel_feed
    assert f"G1 F{m.travel_feed:g}" in lines


@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_aerotech_rotary_is_exact_at_every_filament_end(design):
    profile = ROOT / "machines" / "aerotech_a3200_alicat.toml"
    m = load_machine_profile(profile)
    text, printed, _ = written(design.stem, profile)
    read = parse_gcode(text, m)
    for got, want in zip(read, printed, strict=True):
        c = np.degrees(got.program.nozzle_angle)
        a = np.degrees(want.nozzle_angle)
        shift = 360.0 * np.round((c[0] - a[0]) / 360.0)
        assert abs(c[-1] - a[-1] - shift) <= 1e-3  # the end of each filament (arc or line)
        assert np.max(np.abs(c - a - shift)) <= 1e-3


@pytest.mark.parametrize("profile", PROFILES, ids=lambda p: p.stem)
def test_the_rotary_follows_the_tangent_of_arcs_to_their_ends(profile):
    """Where the nozzle tracks the path, C at every vertex is the designed curve's tangent minus
    the interface angle — the ends of arcs (at a path end, at a join with a line or another arc)
    included, where a chord's heading lags the tangent by half its turning angle (0.48 deg at
    1 mm spacing on a 60 mm radius). On every dialect (the rs274 referee runs the LinuxCNC
    program the same way)."""
    m = load_machine_profile(profile)
    text, _, _ = written("arcs", profile)
    read = parse_gcode(text, m)
    assert len(read) == len(case("arcs")[0])
    off = tangent_errors([got.program for got in read])
    assert len(off) == 3 and max(np.max(np.abs(o)) for o in off) <= 1e-3, off


MARLIN_LIKE = [p for p in PROFILES if load_machine_profile(p).dialect == "marlin"]


@pytest.mark.parametrize("profile", MARLIN_LIKE, ids=lambda p: p.stem)
@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_marlin_like_programs_use_documented_commands_and_axes(design, profile):
    m = load_machine_profile(profile)
    text = _program(design, profile)
    for line in text.splitlines():
        if not line or line.startswith(";"):
            continue
        words = line.split()
        assert words[0] in FIRMWARE[m.controller], line
        if words[0] in ("G0", "G1"):
            assert {w[0] for w in words[1:] if w[0] != "F"} <= MOVE_AXES[m.controller], line
        if words[0] == "G92":
            assert {w[0] for w in words[1:]} <= G92_AXES[m.controller], line
    if m.controller == "klipper":
        assert not re.search(r"^G92\b.*\bC", text, re.M)
