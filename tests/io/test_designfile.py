"""Design files: examples, field-path errors, round trip, schema export."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from rotomorph.errors import InvalidDesignError
from rotomorph.io.designfile import design_schema, load_design, parse_design, save_design

EXAMPLES = sorted((Path(__file__).parents[2] / "examples" / "designs").glob("*.toml"))


def _filament(**segment):
    seg = {"kind": "line", "length": 10.0} | segment
    return {
        "schema_version": 1,
        "filaments": [{"segments": [{"kind": "line", "length": 1.0}] * 2 + [seg]}],
    }


def test_examples_exist():
    names = {p.stem for p in EXAMPLES}
    assert {"janus_bilayer_speeds", "pure_lce_rotation", "composite_rotation", "sinusoids"} <= names
    assert {f"lattice_{p}" for p in ("expanding", "contracting", "dome", "saddle")} <= names


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_loads_and_builds_programs(path):
    design = load_design(path)
    progs = design.to_programs()
    assert progs and all(p.points.shape[1] == 3 for p in progs)
    if design.lattice is not None:
        assert design.lattice.layers == 3 and len(progs) == 30
        assert {p.layer for p in progs} == {0, 1, 2}


def test_paper_parameters_in_examples():
    speeds = [
        p.speed[0]
        for p in load_design(
            EXAMPLES[[p.stem for p in EXAMPLES].index("janus_bilayer_speeds")]
        ).to_programs()
    ]
    assert speeds == [0.25, 0.5, 1.75, 3.0]
    for stem, frac in (("pure_lce_rotation", 1.0), ("composite_rotation", 0.5)):
        progs = load_design(next(p for p in EXAMPLES if p.stem == stem)).to_programs()
        np.testing.assert_allclose([p.rotation_number().mean() for p in progs], [0.06, 0.25, 1, 2])
        assert all(p.active_fraction == frac and p.speed[0] == 3.0 for p in progs)


def test_error_names_the_field_path_and_the_fix():
    with pytest.raises(InvalidDesignError) as info:
        parse_design(_filament(speed=-2))
    assert str(info.value) == "filaments[0].segments[2].speed: must be > 0 mm/s; got -2"
    assert info.value.field == "filaments[0].segments[2].speed"


@pytest.mark.parametrize(
    ("data", "match"),
    [
        ({"filaments": []}, "schema_version: is required"),
        ({"schema_version": 2, "lattice": {}}, "schema_version"),
        ({"schema_version": 1}, "needs"),
        (
            {"schema_version": 1, "lattice": {"n": 5, "colour": "red"}},
            r"lattice\.colour: unknown key",
        ),
        ({"schema_version": 1, "lattice": {"pattern": "custom"}}, "edge_modes"),
        (_filament(kind="spiral"), r"segments\[2\]"),
        (_filament(rotation=1.0, rotation_number=0.2), "at most one"),
        (
            {"schema_version": 1, "lattice": {"amplitude": -1.0}},
            r"lattice\.amplitude: must be >= 0",
        ),
    ],
)
def test_invalid_designs(data, match):
    with pytest.raises(InvalidDesignError, match=match):
        parse_design(data)


def test_bad_toml_is_reported(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("schema_version = = 1\n")
    with pytest.raises(InvalidDesignError, match="not valid TOML"):
        load_design(bad)


def test_save_load_round_trip_is_atomic(tmp_path):
    design = load_design(next(p for p in EXAMPLES if p.stem == "lattice_dome"))
    out = save_design(design, tmp_path / "copy.toml")
    assert [p.name for p in tmp_path.iterdir()] == ["copy.toml"]
    again = load_design(out)
    assert again == design and again.sha256() == design.sha256()
    assert design.gcode_options() == {"pressures": (30.0, 30.0), "design_hash": design.sha256()}


def test_controls_per_segment():
    data = {
        "schema_version": 1,
        "filaments": [
            {
                "speed": 2.0,
                "spacing": 0.5,
                "segments": [
                    {"kind": "line", "length": 5.0, "rotation_number": 0.3},
                    {
                        "kind": "arc",
                        "radius": 4.0,
                        "angle_deg": 90,
                        "interface_angle_deg": 90,
                        "speed": 1.0,
                    },
                    {"kind": "line", "length": 5.0, "rotation": 1.5},
                ],
            }
        ],
    }
    (prog,) = parse_design(data).to_programs()
    s = prog.arc_length
    first, arc, last = s < 4.99, (s > 5.01) & (s < 5 + 2 * np.pi - 0.01), s > 5 + 2 * np.pi + 0.01
    np.testing.assert_allclose(prog.rotation_number()[first], 0.3, rtol=1e-9)
    np.testing.assert_allclose(prog.speed[arc], 1.0)
    np.testing.assert_allclose(prog.rotation[last], 1.5, rtol=1e-9)
    # on the arc the nozzle tracks the heading: α stays at 90° there
    mid_edges = (s[:-1] > 5.6) & (s[1:] < 5 + 2 * np.pi - 0.6)
    wrapped = np.mod(prog.interface_angle[mid_edges] + np.pi, 2 * np.pi) - np.pi
    np.testing.assert_allclose(wrapped, np.pi / 2, atol=1e-9)


def test_schema_export():
    schema = design_schema()
    json.dumps(schema)
    assert schema["properties"]["schema_version"]["const"] == 1
    assert {"filaments", "lattice", "nozzle"} <= set(schema["properties"])
    assert "Filament" in schema["$defs"] and "LatticeModel" in schema["$defs"]


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_example_prints_on_a_default_machine(path):
    from rotomorph.io.gcode import gcode_text
    from rotomorph.io.gcode_read import parse_gcode
    from rotomorph.io.machine import MachineProfile

    design = load_design(path)
    machine = MachineProfile()
    progs = design.to_programs()
    read = parse_gcode(
        gcode_text(progs, machine, layer_cure_s=600, **design.gcode_options()), machine
    )
    assert len(read) == len(progs)
    assert all(
        np.allclose(r.program.points, p.points, atol=1e-4) for r, p in zip(read, progs, strict=True)
    )
