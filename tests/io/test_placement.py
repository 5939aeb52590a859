"""Where a design sits on the machine: new lattices fit by default, and a design outside the
envelope is refused naming the design key to change (not only the machine's)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from rotomorph.cli import main
from rotomorph.errors import MachineLimitError
from rotomorph.io.designfile import parse_design
from rotomorph.io.gcode import gcode_text
from rotomorph.io.machine import MachineProfile, load_machine_profile
from rotomorph.io.placement import check_placement

MACHINES = sorted((Path(__file__).parents[2] / "examples" / "machines").glob("*.toml"))


def _suggested(message: str, key: str) -> list[float]:
    match = re.search(re.escape(key) + r" = \[([^\]]*)\] \(or", message)
    assert match, message
    return [float(x) for x in match.group(1).split(",")]


def test_a_new_lattice_with_default_settings_validates_on_the_default_machine(tmp_path, capsys):
    # before: origin [0, 0, 0] put every new lattice's sine edges below y = 0
    design = parse_design({"schema_version": 1, "lattice": {}})
    check_placement(design, MachineProfile())
    gcode_text(design.to_programs(), MachineProfile(), **design.gcode_options())
    path = tmp_path / "lattice.toml"
    path.write_text("schema_version = 1\n[lattice]\n", encoding="utf-8")
    assert main(["validate", str(path)]) == 0
    assert capsys.readouterr().out.rstrip().endswith("fits machine built-in default")
    assert main(["gcode", str(path), "-o", str(tmp_path / "lattice.gcode")]) == 0
    for profile in MACHINES:  # and on every example machine
        check_placement(design, load_machine_profile(profile))


@pytest.mark.parametrize(
    ("data", "key"),
    [
        ({"lattice": {"origin": [0.0, 0.0, 0.0]}}, "lattice.origin"),
        ({"lattice": {"origin": [290.0, 20.0, 0.0]}}, "lattice.origin"),
        (
            {
                "filaments": [
                    {"start": [10.0, 10.0, 0.0], "segments": [{"kind": "line", "length": 5.0}]},
                    {
                        "start": [10.0, 0.0, 0.0],
                        "segments": [{"kind": "sinusoid", "amplitude": 1.0, "wavelength": 5.0}],
                    },
                ]
            },
            "filaments[1].start",
        ),
    ],
)
def test_an_envelope_refusal_names_the_design_key_and_a_value_that_fits(
    tmp_path, capsys, data, key
):
    design = parse_design({"schema_version": 1, **data})
    with pytest.raises(MachineLimitError, match=re.escape(key)) as err:
        check_placement(design, MachineProfile())
    # the G-code writer refuses the same design (the check only names the key first)
    with pytest.raises(MachineLimitError):
        gcode_text(design.to_programs(), MachineProfile(), **design.gcode_options())
    fixed = _suggested(str(err.value), key)
    if key == "lattice.origin":
        moved = {"lattice": {**data["lattice"], "origin": fixed}}
    else:
        fils = [dict(f) for f in data["filaments"]]
        fils[1]["start"] = fixed
        moved = {"filaments": fils}
    check_placement(parse_design({"schema_version": 1, **moved}), MachineProfile())
    # on the command line: one line, exit 2, the key named
    import tomli_w

    path = tmp_path / "design.toml"
    path.write_text(tomli_w.dumps({"schema_version": 1, **data}), encoding="utf-8")
    assert main(["gcode", str(path), "-o", str(tmp_path / "d.gcode")]) == 2
    errors = [x for x in capsys.readouterr().err.splitlines() if "error:" in x]
    assert len(errors) == 1 and key in errors[0] and "machine limits" in errors[0]


def test_a_design_larger_than_the_envelope_names_the_machine_keys():
    design = parse_design({"schema_version": 1, "lattice": {"n": 12, "spacing": 30.0}})
    with pytest.raises(MachineLimitError, match="does not fit this machine") as err:
        check_placement(design, MachineProfile())
    assert "lattice.origin" in str(err.value) and "key 'envelope_max'" in str(err.value)
