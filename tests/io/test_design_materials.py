"""A design that names its own materials file runs through validate, predict, simulate, gcode,
sweeps and inverse alike.

The lab's file here is the paper's with its inks renamed (``rm257``, ``pdms``): every number is
the same, so every result must equal the paper inks' result exactly, and a changed value must
change it; names, hashes and errors must follow the lab's file.
"""

from __future__ import annotations

import copy
import json
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import rotomorph
from rotomorph.cli import main
from rotomorph.errors import InvalidDesignError
from rotomorph.io.designfile import load_design, parse_design
from rotomorph.io.materials_file import load_materials, save_materials
from rotomorph.materials.parameter_set import materials_from_mapping

try:
    import tomllib
except ModuleNotFoundError:  # pragma: no cover
    import tomli as tomllib  # type: ignore[no-redef]

PAPER_DOC = tomllib.loads(
    resources.files("rotomorph.materials").joinpath("data/paper_inks.toml").read_text("utf-8")
)


def lab_document(gain: float | None = None) -> dict:
    doc = copy.deepcopy(PAPER_DOC)
    doc["name"] = "lab-inks"
    doc["inks"] = {"rm257": doc["inks"]["lce"], "pdms": doc["inks"]["acrylate"]}
    doc["inks"]["rm257"]["actuated_modulus_ratio"]["relative_to"] = "pdms"
    cal = doc["calibration"]
    cal["parameters"] = [
        p.replace("lce.", "rm257.").replace("acrylate.", "pdms.") for p in cal["parameters"]
    ]
    if gain is not None:
        doc["inks"]["rm257"]["strain_gain"]["value"] = gain
    return doc


FILAMENTS = """schema_version = 1
name = "two"
{materials}
[[filaments]]
name = "w=0.25"
speed = 3.0
rotation_number = 0.25
spacing = 0.5
{inks}
segments = [{{ kind = "line", length = 12.0 }}]

[[filaments]]
name = "janus"
speed = 1.0
spacing = 0.5
{inks}
segments = [{{ kind = "line", length = 8.0 }}]
"""
LAB_INKS = 'active_material = "rm257"\npassive_material = "pdms"'


@pytest.fixture()
def lab(tmp_path: Path) -> Path:
    """A folder with the lab's materials file, a design naming it, and the paper twin."""
    (tmp_path / "inks").mkdir()
    save_materials(materials_from_mapping(lab_document()), tmp_path / "inks" / "lab.toml")
    (tmp_path / "design.toml").write_text(
        FILAMENTS.format(materials='materials = "inks/lab.toml"', inks=LAB_INKS), encoding="utf-8"
    )
    (tmp_path / "paper.toml").write_text(FILAMENTS.format(materials="", inks=""), encoding="utf-8")
    return tmp_path


def test_validate_names_the_file_and_checks_the_inks(lab, capsys) -> None:
    assert main(["validate", str(lab / "design.toml")]) == 0
    out = capsys.readouterr().out
    assert "materials 'lab-inks' (rm257, pdms; sha256 " in out
    assert main(["validate", str(lab / "inks" / "lab.toml")]) == 0
    out = capsys.readouterr().out
    assert "valid materials file 'lab-inks' version 1: rm257 (active), pdms (passive)" in out
    design = load_design(lab / "design.toml")
    assert design.material_set == load_materials(lab / "inks" / "lab.toml")
    # the paper's names are not the lab's: one line naming the file's inks
    text = FILAMENTS.format(materials='materials = "inks/lab.toml"', inks="")
    (lab / "wrong.toml").write_text(text, encoding="utf-8")
    assert main(["validate", str(lab / "wrong.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "active_material: unknown material 'lce' in materials" in err
    assert "use one of rm257, pdms" in err


@pytest.mark.parametrize(
    ("entry", "fragment"),
    [
        ('"missing.toml"', "materials: missing.toml: no such file"),
        ('"inks"', "materials: inks: is not a file"),
        ('"bad.toml"', "materials: bad.toml: inks.rm257.youngs_modulus.unit: 'psi' is not a unit"),
        ("3", "materials: must be"),
        ('"in\\u001b[2Jks.toml"', "materials: must not hold control"),
        ('"in\\u202eks.toml"', "found U+202E (RIGHT-TO-LEFT OVERRIDE)"),
    ],
)
def test_a_bad_materials_entry_is_one_line(lab, capsys, entry, fragment) -> None:
    text = (lab / "inks" / "lab.toml").read_text("utf-8").replace('unit = "MPa"', 'unit = "psi"', 1)
    (lab / "bad.toml").write_text(text, encoding="utf-8")
    design = FILAMENTS.format(materials=f"materials = {entry}", inks=LAB_INKS)
    (lab / "d.toml").write_text(design, encoding="utf-8")
    assert main(["validate", str(lab / "d.toml")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err
    assert err[:-1].isprintable(), err


def test_hashes_follow_the_inks(lab) -> None:
    design = load_design(lab / "design.toml")
    paper = load_design(lab / "paper.toml")
    assert paper.material_set is None and "materials" not in paper.model_dump()
    changed = materials_from_mapping(lab_document(gain=2.5))
    save_materials(changed, lab / "inks" / "lab.toml")
    again = load_design(lab / "design.toml")
    assert again.sha256() != design.sha256()  # the same text, other inks
    inline = parse_design({**design.model_dump(), "materials": lab_document(gain=2.5)})
    assert inline.material_set == changed


def test_predict_is_the_paper_model_with_the_lab_names_and_follows_its_values(lab) -> None:
    same = rotomorph.predict(lab / "design.toml")
    paper = rotomorph.predict(lab / "paper.toml")
    assert [s.end_to_end_ratio for s in same] == [s.end_to_end_ratio for s in paper]
    assert [s.curvature for s in same] == [s.curvature for s in paper]
    save_materials(materials_from_mapping(lab_document(gain=2.5)), lab / "inks" / "lab.toml")
    other = rotomorph.predict(lab / "design.toml")
    assert all(o.curvature > p.curvature for o, p in zip(other, paper, strict=True))
    named = rotomorph.predict(lab / "design.toml", model="warner-terentjev")
    assert [s.curvature for s in named] != [s.curvature for s in other]


def test_simulate_records_the_set_and_equals_the_paper_twin(lab, tmp_path) -> None:
    sim = rotomorph.simulate(lab / "design.toml", steps=2)
    twin = rotomorph.simulate(lab / "paper.toml", steps=2)
    assert np.array_equal(sim.positions, twin.positions)
    inks = load_materials(lab / "inks" / "lab.toml")
    assert sim.metadata["materials"]["sha256"] == inks.sha256
    assert twin.metadata["materials"]["default"] is True
    out = tmp_path / "run"
    assert (
        main(["simulate", str(lab / "design.toml"), "-o", str(out), "--steps", "2", "--no-movie"])
        == 0
    )
    summary = json.loads((out / "summary.json").read_text())
    assert json.dumps(summary).count(inks.sha256) >= 1


def test_gcode_names_the_file_and_refuses_foreign_inks(lab, tmp_path, capsys) -> None:
    out = tmp_path / "lab.gcode"
    assert main(["gcode", str(lab / "design.toml"), "-o", str(out), "--dialect", "rs274"]) == 0
    text = out.read_text("ascii")
    inks = load_materials(lab / "inks" / "lab.toml")
    assert f"; materials: lab-inks version 1 sha256 {inks.sha256}" in text
    assert "active_material=rm257 passive_material=pdms" in text
    from rotomorph.io.gcode import check_materials

    programs = load_design(lab / "paper.toml").to_programs()
    with pytest.raises(rotomorph.MaterialError, match="unknown material 'lce' in materials"):
        check_materials(programs, inks)


def test_a_lattice_with_the_lab_inks_runs_as_the_paper_twin(lab) -> None:
    body = "[lattice]\nn = 2\nghost_nodes = 3\nlayers = 1\n"
    (lab / "lat.toml").write_text(
        f'schema_version = 1\nmaterials = "inks/lab.toml"\n{body}{LAB_INKS}\n', encoding="utf-8"
    )
    (lab / "lat_paper.toml").write_text(f"schema_version = 1\n{body}", encoding="utf-8")
    a = rotomorph.simulate(lab / "lat.toml", steps=2)
    b = rotomorph.simulate(lab / "lat_paper.toml", steps=2)
    assert np.allclose(a.positions, b.positions, rtol=0, atol=1e-12)


def test_a_sweep_carries_the_inks_and_hashes_them(lab, tmp_path) -> None:
    from rotomorph.sweep import load_sweep, run_sweep

    sweep = lab / "sweep.toml"
    sweep.write_text(
        'schema_version = 1\nname = "s"\ndesign = "design.toml"\n'
        'outputs = ["filaments[0].end_to_end_ratio"]\n'
        '[settings]\nmethod = "closed_form"\n[[parameters]]\npath = "filaments[0].speed"\n'
        "values = [1.0, 3.0]\n",
        encoding="utf-8",
    )
    spec = load_sweep(sweep)
    assert isinstance(spec.design["materials"], dict)  # read in: runs need no file
    rows = run_sweep(spec, tmp_path / "sweep", workers=1).table.to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok"]
    assert rows[0]["filaments[0].end_to_end_ratio"] != rows[1]["filaments[0].end_to_end_ratio"]
    save_materials(materials_from_mapping(lab_document(gain=2.5)), lab / "inks" / "lab.toml")
    other = run_sweep(load_sweep(sweep), tmp_path / "sweep2", workers=1).table.to_pylist()
    assert {r["run_id"] for r in other}.isdisjoint({r["run_id"] for r in rows})
    assert other[0]["filaments[0].end_to_end_ratio"] != rows[0]["filaments[0].end_to_end_ratio"]
    text = sweep.read_text().replace(
        'method = "closed_form"',
        'method = "closed_form"\nfilament_model = "calibrated-without-janus_curvature"',
    )
    sweep.write_text(text)
    refused = run_sweep(load_sweep(sweep), tmp_path / "sweep3", workers=1).table.to_pylist()
    assert {r["status"] for r in refused} == {"invalid"}
    assert "paper's inks" in refused[0]["error_message"]


def test_inverse_designs_with_the_lab_inks_and_names_them(lab, tmp_path, capsys) -> None:
    target = lab / "helix.toml"
    target.write_text(
        'schema_version = 1\nkind = "curve"\nmaterials = "inks/lab.toml"\n[curve]\n'
        'family = "helix"\nradius_start = 2.0\nradius_end = 2.2\npitch = 1.5\nturns = 1.0\n'
        '[options]\nactive_material = "rm257"\npassive_material = "pdms"\n',
        encoding="utf-8",
    )
    out = tmp_path / "designs" / "helix.toml"
    assert main(["inverse", str(target), "-o", str(out)]) == 0
    design = load_design(out)
    assert design.material_set == load_materials(lab / "inks" / "lab.toml")
    assert design.filaments[0].active_material == "rm257"
    assert not Path(str(design.materials)).is_absolute()
    summary = json.loads((tmp_path / "designs" / "helix_inverse" / "summary.json").read_text())
    assert summary["rms_error_rel"] < 0.005  # the default tolerance of options.tolerance
    with pytest.raises(InvalidDesignError, match=r"options\.active_material"):
        from rotomorph.inverse.targets import parse_target

        parse_target(
            {
                "schema_version": 1,
                "kind": "curve",
                "materials": "inks/lab.toml",
                "curve": {
                    "family": "helix",
                    "radius_start": 2.0,
                    "radius_end": 2.2,
                    "pitch": 1.5,
                    "turns": 1.0,
                },
            },
            lab,
        )


def test_the_predict_command_gives_the_paper_twins_numbers_and_band(lab, capsys) -> None:
    assert main(["predict", str(lab / "design.toml"), "--json"]) == 0
    mine = json.loads(capsys.readouterr().out)
    assert main(["predict", str(lab / "paper.toml"), "--json"]) == 0
    twin = json.loads(capsys.readouterr().out)
    assert mine["materials"]["sha256"] == load_materials(lab / "inks" / "lab.toml").sha256
    assert twin["materials"] is None
    for a, b in zip(mine["filaments"], twin["filaments"], strict=True):
        assert a["method"] == b["method"] and not a["extrapolation"]
        for key, q in a["quantities"].items():
            ref = b["quantities"][key]
            assert q["value"] == pytest.approx(ref["value"], rel=1e-9, abs=1e-12), key
            assert q["sd_calibration"] == pytest.approx(ref["sd_calibration"], rel=1e-6), key


def test_the_predict_command_says_which_file_and_band(lab, capsys) -> None:
    sha = load_materials(lab / "inks" / "lab.toml").sha256
    assert main(["predict", str(lab / "design.toml")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[1].startswith(f"materials 'lab-inks' version 1 (sha256 {sha[:12]}): ± is ")
    assert "posterior covariance of rm257.actuated_modulus_ratio" in lines[1]
    assert all(" ± " in line for line in lines[2:]), lines
    doc = lab_document()
    del doc["calibration"]  # a file without a stored calibration: values, no band
    save_materials(materials_from_mapping(doc), lab / "inks" / "lab.toml")
    assert main(["predict", str(lab / "design.toml"), "--json"]) == 0
    record = json.loads(capsys.readouterr().out)
    assert record["band"].startswith("none: the materials file stores no calibration covariance")
    for filament in record["filaments"]:
        assert all(q["sd_calibration"] is None for q in filament["quantities"].values())
    assert main(["predict", str(lab / "design.toml")]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert "± is none" in lines[1] and not any(" ± " in line for line in lines[2:]), lines
