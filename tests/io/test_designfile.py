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
        np.testing.assert_allclose([p.rotation_number.mean() for p in progs], [0.06, 0.25, 1, 2])
        assert all(p.active_fraction == frac and p.speed[0] == 3.0 for p in progs)


def test_error_names_the_field_path_and_the_fix():
    with pytest.raises(InvalidDesignError) as info:
        parse_design(_filament(speed=-2))
    assert str(info.value) == "filaments[0].segments[2].speed: must be >= 0.01 mm/s; got -2"
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
    from rotomorph.io.gcode import Process

    options = design.gcode_options()
    assert options["design_hash"] == design.sha256()
    assert options["process"] == [Process(30.0, 30.0)] * len(design.to_programs())
    # defaults nobody set stay placeholders through a save (the G-code header flags them)
    assert all(p.placeholders for p in again.gcode_options()["process"])
    assert [p.placeholders for p in again.gcode_options()["process"]] == [
        p.placeholders for p in options["process"]
    ]


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
    np.testing.assert_allclose(prog.rotation_number[first], 0.3, rtol=1e-9)
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
    from rotomorph.io.gcode import gcode_text, plan_programs
    from rotomorph.io.gcode_read import parse_gcode
    from rotomorph.io.machine import MachineProfile

    design = load_design(path)
    machine = MachineProfile()
    progs = design.to_programs()
    read = parse_gcode(
        gcode_text(progs, machine, layer_cure_s=600, **design.gcode_options()), machine
    )
    assert len(read) == len(progs)
    printed = plan_programs(progs, machine)
    assert all(
        np.allclose(r.program.points, p.points, atol=1e-4)
        for r, p in zip(read, printed, strict=True)
    )


# ----------------------------------------------------------------------------- robust input


def _one(**fil):
    return {
        "schema_version": 1,
        "filaments": [{"segments": [{"kind": "line", "length": 10.0}]} | fil],
    }


@pytest.mark.parametrize(
    ("fil", "match"),
    [
        ({"speed": True}, r"filaments\[0\]\.speed: must be a number \(mm/s\); got True \(bool\)"),
        ({"speed": "3"}, r"speed: must be a number \(mm/s\) without quotes; got '3'"),
        ({"layer": True}, r"layer: must be a whole number; got True"),
        ({"layer": 1.0}, r"layer: must be a whole number; got 1.0"),
        ({"start": [0, 0, True]}, r"start\[2\]: must be a number"),
        ({"start": [0, 0]}, r"start: .*3 numbers"),
        ({"name": 5}, r"name: must be a text string"),
    ],
)
def test_strict_types_no_coercion(fil, match):
    with pytest.raises(InvalidDesignError, match=match):
        parse_design(_one(**fil))


@pytest.mark.parametrize(
    ("data", "match"),
    [
        (_one(rotation=1e12), r"filaments\[0\]\.rotation: must be <= 1000 rad/s"),
        (_one(radius=1e6), r"filaments\[0\]\.radius: must be <= 10 mm"),
        (_one(speed=0), r"speed: must be >= 0.01 mm/s; got 0"),
        (_one(speed=1e-9), r"speed: must be >= 0.01 mm/s"),
        (_one(start=[1e12, 0, 0]), r"start\[0\]: must be <= 10000 mm"),
        (_one(active_fraction=0), r"active_fraction: must be > 0"),
        (_one(active_material="acrylate"), r"active_material: 'acrylate' is a passive material"),
        (_one(passive_material="unobtainium"), r"passive_material: unknown material"),
        (_one(spacing=20.0), r"filaments\[0\]: has 2 vertices .* needs >= 3"),
        ({"schema_version": True, "lattice": {}}, r"schema_version: must be 1; got True"),
        ({"schema_version": 1, "lattice": {"n": 1e20}}, r"lattice\.n: must be a whole number"),
        ({"schema_version": 1, "lattice": {"n": 10**20}}, r"lattice\.n: must be <= 10000"),
        ({"schema_version": 1, "nozzle": {"active_pressure": 1e9}, "lattice": {}}, "<= 1000 psi"),
        (_one() | {"lattice": {}}, "not both; split it"),
    ],
)
def test_absurd_values_are_refused(data, match):
    with pytest.raises(InvalidDesignError, match=match):
        parse_design(data)


def test_oversized_design_is_refused_before_building_with_the_numbers():
    from rotomorph.io.design_limits import MAX_NODES

    with pytest.raises(InvalidDesignError) as info:
        parse_design({"schema_version": 1, "lattice": {"n": 500}})
    msg = str(info.value)
    assert msg.startswith("lattice: too large: about 5,240,000 rod nodes")
    assert f"the limit is {MAX_NODES:,} nodes" in msg and "GB of memory" in msg
    long = _one(spacing=0.001)
    long["filaments"][0]["segments"] = [{"kind": "line", "length": 9999.0}]
    with pytest.raises(InvalidDesignError, match=r"filaments\[0\]: too large: about 9,999,001"):
        parse_design(long)


def test_node_estimate_matches_the_built_design():
    from rotomorph.io.designfile import design_size

    for path in EXAMPLES:
        design = load_design(path)
        if design.lattice is not None:
            built = design.lattice.to_lattice().network.n_nodes
        else:
            built = sum(len(p.points) for p in design.to_programs())
        assert design_size(design).nodes == built, path.stem


@pytest.mark.parametrize(
    ("blob", "match"),
    [
        ("schema_version = 1\nname = 'é'\n[lattice]\n".encode("latin-1"), "not UTF-8 text .*0xe9"),
        (b"schema_version = 1\n[lattice]\nn = \xff\n", "not UTF-8 text"),
        (b"\xff\xfe" + "schema_version = 1\n[lattice\n".encode("utf-16-le"), "not valid TOML"),
        (b"schema_version = 1\n" + b"a = " + b"[" * 3000, "not valid TOML"),
        (b"\x00\x01", "not valid TOML"),
    ],
)
def test_undecodable_files_are_one_line_errors(tmp_path, blob, match):
    path = tmp_path / "d.toml"
    path.write_bytes(blob)
    with pytest.raises(InvalidDesignError, match=match) as info:
        load_design(path)
    assert "\n" not in str(info.value) and info.value.field == str(path)


def test_utf16_and_bom_files_are_read(tmp_path):
    text = "schema_version = 1\nname = 'Größe'\n[lattice]\nn = 3\n"
    for i, blob in enumerate((text.encode("utf-16"), b"\xef\xbb\xbf" + text.encode())):
        (tmp_path / f"{i}.toml").write_bytes(blob)
        assert load_design(tmp_path / f"{i}.toml").name == "Größe"


def test_with_spacing_revalidates():
    from rotomorph.io.designfile import with_spacing

    design = parse_design(_one())
    assert with_spacing(design, 0.5).filaments[0].spacing == 0.5
    with pytest.raises(InvalidDesignError, match=r"spacing: must be >= 0.001 mm"):
        with_spacing(design, 0.0)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ('[machine]\nmax_feed = "50"\n', r"max_feed.* wrong type str; got '50'"),
        ("[machine]\nmax_feed = true\n", r"max_feed.* wrong type bool; got True"),
        ("[machine]\nenvelope_min = [0, 0]\n", r"envelope_m"),
        ("[machine\nmax_feed = 5\n", r"not valid TOML"),
        ("[machine]\npressure_template = 'P{port} Q{psi:.3q}'\n", "not a valid template"),
        ("[machine]\npressure_template = 'P{port} Q{psi} {'\n", "not a valid template"),
        ("machine = 3\n", r"must be a table"),
    ],
)
def test_bad_machine_profiles(tmp_path, text, match):
    from rotomorph.errors import InvalidParameterError
    from rotomorph.io.machine import load_machine_profile

    path = tmp_path / "m.toml"
    path.write_text(text)
    with pytest.raises(InvalidParameterError, match=match):
        load_machine_profile(path)
    path.write_bytes("[machine]\nname = 'Fräse'\n".encode("latin-1"))
    with pytest.raises(InvalidParameterError, match="not UTF-8"):
        load_machine_profile(path)


def test_keys_with_control_characters_give_one_line_errors():
    with pytest.raises(InvalidDesignError) as info:
        parse_design({"schema_version": 1, "lattice": {"a\nb\x00": 1}})
    assert "\n" not in str(info.value) and "a\\nb\\x00" in info.value.field


def test_lattice_edge_speeds_reach_the_programs_and_the_gcode():
    """Per-edge speeds: every move along an edge is written at that edge's feed."""
    from rotomorph.io.gcode import gcode_text
    from rotomorph.io.machine import MachineProfile

    speeds = [0.5 + 0.25 * e for e in range(12)]
    lat = {"n": 3, "ghost_nodes": 4, "edge_speeds": speeds, "origin": [10.0, 10.0, 0.0]}
    design = parse_design({"schema_version": 1, "lattice": lat})
    lattice = design.lattice.to_lattice()
    assert np.allclose(lattice.speeds, speeds)
    progs = design.to_programs()
    # x-line j = 0 prints edges 0, 1: the moves of edge e (5 segments x 4 subdivisions) at v_e
    assert np.allclose(progs[0].speed[:-1], np.repeat(speeds[:2], 20))
    text = gcode_text(progs, MachineProfile())
    words = [w for line in text.splitlines() if line.startswith("G1") for w in line.split()]
    feeds = {float(w[1:]) for w in words if w[:1] == "F"}
    assert {round(v, 4) for v in speeds} <= feeds
    # the design file keeps them through a save/load round trip
    assert parse_design(json.loads(design.model_dump_json())).lattice.edge_speeds == speeds


@pytest.mark.parametrize(
    ("speeds", "match"),
    [
        ([1.0] * 11, r"lattice: edge_speeds needs one speed per lattice edge \(12\); got 11"),
        ([1.0] * 11 + [0.0], r"lattice\.edge_speeds\[11\]: must be >= 0\.01"),
        ([1.0] * 11 + ["3"], r"lattice\.edge_speeds\[11\]: must be a number"),
    ],
)
def test_bad_lattice_edge_speeds_are_one_line_errors(speeds, match):
    data = {"schema_version": 1, "lattice": {"n": 3, "ghost_nodes": 4, "edge_speeds": speeds}}
    with pytest.raises(InvalidDesignError, match=match) as err:
        parse_design(data)
    assert "\n" not in str(err.value)


def test_a_filament_with_arcs_tracks_their_tangent_and_others_are_unchanged():
    from rotomorph.design.program import PrintProgram

    # no example has an arc: their programs are the polygon's, as before
    for path in EXAMPLES:
        assert not any(p.has_tangents for p in load_design(path).to_programs())
    d = parse_design(
        {
            "schema_version": 1,
            "filaments": [
                {
                    "interface_angle_deg": 20.0,
                    "spacing": 1.0,
                    "segments": [
                        {"kind": "line", "length": 5.0},
                        {"kind": "arc", "radius": 60.0, "angle_deg": 30.0},
                    ],
                }
            ],
        }
    )
    prog = d.to_programs()[0]
    assert prog.has_tangents
    assert prog.nozzle_angle[-1] == pytest.approx(np.radians(30.0 - 20.0))  # the arc's end
    polygon = PrintProgram.from_interface_angle(prog.points, 3.0, np.radians(20.0))
    np.testing.assert_allclose(prog.nozzle_angle[1:-1][:4], polygon.nozzle_angle[1:-1][:4])
    assert abs(polygon.nozzle_angle[-1] - prog.nozzle_angle[-1]) > np.radians(0.4)


def test_program_names_follow_the_programs():
    d = load_design(Path(__file__).parents[2] / "examples" / "designs" / "lattice_dome.toml")
    lattice = d.lattice
    for name, prog in zip(d.program_names(), d.to_programs(), strict=True):
        line, layer = name.split(", layer ")
        axis, index = line.split("-line ")
        along, across = (0, 1) if axis == "x" else (1, 0)
        assert np.ptp(prog.points[:, along]) > 3 * np.ptp(prog.points[:, across])
        offset = prog.points[0, across] - lattice.origin[across]
        assert offset == pytest.approx(int(index) * lattice.spacing)
        assert prog.layer == int(layer)
    d = load_design(Path(__file__).parents[2] / "examples" / "designs" / "sinusoids.toml")
    assert d.program_names() == [f.name for f in d.filaments]
