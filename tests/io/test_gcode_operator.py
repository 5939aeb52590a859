"""G-code as the printer's operator reads it: the header states the units the program uses."""

from __future__ import annotations

import re
from dataclasses import replace
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
    machine = load_machine_profile(profile)
    lamp = replace(machine, uv_on_template="M7", uv_off_template="M9")  # a lamp: a timed cure
    text = _program(lamp, cure=12.5)
    unit = re.search(r"^; units: .*, dwell (\w+)$", text, re.M)
    assert unit is not None
    dwells = re.findall(r"^G4 P(\S+)$", text, re.M)
    assert dwells, "the cure dwell is written"
    assert {float(p) for p in dwells} == {12500.0 if unit[1] == "ms" else 12.5}


@pytest.mark.parametrize("profile", PROFILES, ids=lambda p: p.stem)
def test_a_cure_without_lamp_commands_is_a_real_pause(profile):
    # before: a blind 60 s dwell with "switch the lamp by hand" in a comment
    machine = load_machine_profile(profile)
    text = _program(machine, cure=5.0)
    pause = {"a3200": "M0", "linuxcnc": "M0", "marlin": "M0", "klipper": "PAUSE"}
    pause["reprapfirmware"] = "M226"
    assert machine.pause_template == pause[machine.controller]
    head = "; UV cure after layer 0: 5 s by hand (no lamp commands in the machine profile): the "
    assert f"{head}program pauses ({machine.pause_template}); switch the lamp on" in text
    assert f"then resume\n{machine.pause_template}\n" in text
    assert not re.search(r"^G4 P5(000)?$", text, re.M)  # no blind dwell


def test_a_cure_with_lamp_commands_switches_the_lamp():
    lamp = MachineProfile(dialect="rs274", uv_on_template="M7", uv_off_template="M9")
    text = _program(lamp, cure=5.0)
    assert "; UV cure after layer 0: 5 s\nM7\nG4 P5\nM9\n" in text


def test_checking_a_program_against_another_dialect_says_so():
    # before: "line 15: unexpected command: 'G94'" (an RS-274 program checked as Marlin)
    from rotomorph.errors import GcodeParseError
    from rotomorph.io.gcode_read import check_gcode

    machines = ROOT / "examples" / "machines"
    text = _program(load_machine_profile(machines / "linuxcnc.toml"), cure=0.0)
    with pytest.raises(GcodeParseError, match=r"^line 7: the program was written for the 'rs274'"):
        check_gcode(text, load_machine_profile(machines / "marlin.toml"))


def test_checking_a_program_against_another_machine_of_its_dialect_names_both():
    from rotomorph.errors import GcodeParseError
    from rotomorph.io.gcode_read import check_gcode

    machines = ROOT / "examples" / "machines"
    text = _program(load_machine_profile(machines / "marlin.toml"), cure=0.0)
    rrf = load_machine_profile(machines / "reprapfirmware.toml")
    with pytest.raises(GcodeParseError) as err:
        check_gcode(text, rrf)
    assert str(err.value).startswith("line 22: unknown pressure port 4: 'M42 P4 S0' (the program ")
    assert "header line 4: 'machine: Marlin rotational printer, profile marlin.toml'" in str(
        err.value
    )
    assert str(err.value).endswith("the profile is 'RepRapFirmware rotational printer')")
    check_gcode(text, load_machine_profile(machines / "marlin.toml"))  # its own profile: fine
