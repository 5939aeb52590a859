"""G-code as the printer's operator reads it: the header states the units the program uses."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rotomorph.io.designfile import load_design
from rotomorph.io.gcode import gcode_text
from rotomorph.io.machine import MachineProfile, load_machine_profile

ROOT = Path(__file__).resolve().parents[2]
PROFILES = sorted((ROOT / "examples" / "machines").glob("*.toml"))


def _program(machine: MachineProfile, cure: float) -> str:
    design = load_design(ROOT / "examples" / "designs" / "sinusoids.toml")
    return gcode_text(design.to_programs(), machine, layer_cure_s=cure, **design.gcode_options())


@pytest.mark.parametrize("profile", PROFILES, ids=lambda p: p.stem)
def test_header_dwell_unit_is_the_unit_of_the_written_dwells(profile):
    # before: every header said "dwell s" while Marlin, Klipper and RepRapFirmware programs
    # write G4 P<ms>: an operator read 'G4 P12500' as a dwell of 12500 s
    text = _program(load_machine_profile(profile), cure=12.5)
    unit = re.search(r"^; units: .*, dwell (\w+)$", text, re.M)
    assert unit is not None
    dwells = re.findall(r"^G4 P(\S+)$", text, re.M)
    assert dwells, "the cure dwell is written"
    assert {float(p) for p in dwells} == {12500.0 if unit[1] == "ms" else 12.5}


def test_a_cure_without_uv_commands_says_the_lamp_is_switched_by_hand():
    plain = _program(MachineProfile(dialect="rs274"), cure=5.0)
    assert "; UV cure after layer 0: 5 s (no UV command in the machine profile: switch" in plain
    lamp = MachineProfile(dialect="rs274", uv_on_template="M7", uv_off_template="M9")
    text = _program(lamp, cure=5.0)
    assert "; UV cure after layer 0: 5 s\nM7\nG4 P5\nM9\n" in text


def test_checking_a_program_against_another_dialect_says_so():
    # before: "line 15: unexpected command: 'G94'" (an RS-274 program checked as Marlin)
    from rotomorph.errors import GcodeParseError
    from rotomorph.io.gcode_read import check_gcode

    machines = ROOT / "examples" / "machines"
    text = _program(load_machine_profile(machines / "linuxcnc.toml"), cure=0.0)
    with pytest.raises(GcodeParseError, match=r"^line 6: the program was written for the 'rs274'"):
        check_gcode(text, load_machine_profile(machines / "marlin.toml"))


def test_checking_a_program_against_another_machine_of_its_dialect_names_both():
    from rotomorph.errors import GcodeParseError
    from rotomorph.io.gcode_read import check_gcode

    machines = ROOT / "examples" / "machines"
    text = _program(load_machine_profile(machines / "marlin.toml"), cure=0.0)
    klipper = load_machine_profile(machines / "klipper.toml")
    with pytest.raises(GcodeParseError) as err:
        check_gcode(text, klipper)
    assert str(err.value).startswith("line 20: unexpected command: 'M42 P4 S76' (the program ")
    assert "header line 4: 'machine: Marlin rotational printer, profile marlin.toml'" in str(
        err.value
    )
    assert str(err.value).endswith("the profile is 'Klipper rotational printer')")
    check_gcode(text, load_machine_profile(machines / "marlin.toml"))  # its own profile: fine
