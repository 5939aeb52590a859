"""``rotomorph calibrate``: tables in, a materials file, its report and figures out; the design
that names the file prints; bad input exits 2 with one line."""

from __future__ import annotations

import io
import json
import logging
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import pytest

from rotomorph.cli import main
from rotomorph.io.materials_file import load_materials

ROOT = Path(__file__).resolve().parents[2]
INKS = ROOT / "examples" / "inks"
TABLES = [str(INKS / n) for n in ("filaments.csv", "inks.csv", "sinusoids.csv")]


#: What the module's calibration printed (``out``: stdout, ``err``: its progress with -v).
PRINTED: dict[str, str] = {}


@pytest.fixture(scope="module")
def calibrated(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("cal") / "lab" / "inks.toml"
    stdout, stderr = io.StringIO(), io.StringIO()
    library = logging.getLogger("rotomorph")  # as -v does (pytest's handlers keep basicConfig off)
    level = library.level
    library.setLevel(logging.INFO)
    try:
        with redirect_stdout(stdout), redirect_stderr(stderr):
            assert main(["-v", "calibrate", *TABLES, "-o", str(out)]) == 0
    finally:
        library.setLevel(level)
    PRINTED.update(out=stdout.getvalue(), err=stderr.getvalue())
    return out


def test_says_what_the_tables_determine_before_and_after_the_fit(calibrated) -> None:
    out, err = PRINTED["out"].splitlines(), PRINTED["err"]
    assert out[0].startswith(f"wrote {calibrated} and ") and out[1].startswith("what the tables")
    said = {line.strip().split(":")[0]: line for line in out[2:]}
    assert "stays at its prior" in said["T_NI"] and "free_length of the active ink" in said["T_NI"]
    assert "stays at its prior" in said["transition width"], said
    for label in ("strain-law gain", "strain-law threshold S0", "E_a/E_p at actuation"):
        assert said[label].strip().startswith(f"{label}: determined by "), said[label]
    assert out[-1].strip().startswith("singular values of the prior-scaled sensitivities")
    before = err.index("what the tables determine, before fitting:")
    assert before < err.index("fitting (both branches") and "T_NI: stays at its prior" in err


def test_writes_the_file_report_and_figures(calibrated, capsys) -> None:
    inks = load_materials(calibrated)
    assert inks.names() == ("lce", "acrylate") and inks.name == "inks"
    folder = calibrated.with_name("inks_calibration")
    report = (folder / "calibration.md").read_text("utf-8")
    for section in (
        "## What the tables determine",
        "## The two branches of the bilayer symmetry",
        "## Fitted values and their priors",
        "### janus_curvature",
        "predicted without this table",
        "## Validation only (never fitted)",
        "## Where the model is measured (extrapolation ranges)",
        "T\\_NI: stays at its prior",
    ):
        assert section in report, section
    for name in ("janus_curvature", "pure_lce_length", "composite_length", "residuals"):
        assert (folder / f"{name}.png").stat().st_size > 10_000
    record = json.loads((folder / "calibration.json").read_text())
    assert record["materials"]["sha256"] == inks.sha256
    assert {v["quantity"] for v in record["validation"]} == {"sinusoid_end_to_end"}
    assert all(v["predicted"] is not None for v in record["validation"])
    # the committed example is this very calibration (a fresh run reproduces its values)
    example = load_materials(INKS / "inks.toml")
    fresh = {(r.owner, r.key): r for r in inks.values()}
    stored = {(r.owner, r.key): r for r in example.values()}
    assert fresh.keys() == stored.keys()
    for key, r in stored.items():
        assert r.provenance == fresh[key].provenance and r.unit == fresh[key].unit, key
        if isinstance(r.value, float):
            assert r.value == pytest.approx(fresh[key].value, rel=1e-6, abs=1e-12), key
    assert example.document.calibration.data_sha256 == inks.document.calibration.data_sha256


def test_a_design_naming_the_file_validates_and_prints(calibrated, tmp_path, capsys) -> None:
    design = INKS / "lattice.toml"
    assert main(["validate", str(design)]) == 0
    assert "materials 'inks'" in capsys.readouterr().out
    gcode = tmp_path / "lattice.gcode"
    assert main(["gcode", str(design), "-o", str(gcode), "--dialect", "rs274"]) == 0
    assert "; materials: inks version 1 sha256" in gcode.read_text("ascii")


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["calibrate", str(INKS / "inks.csv"), "-o", "x.json"], "ending in .toml"),
        (["calibrate", "missing.csv", "-o", "x.toml"], "MEASUREMENTS: missing.csv: no such file"),
        (["calibrate", str(INKS / "inks.csv"), "-o", "x.toml", "--radius", "0"], "--radius"),
        (["calibrate", str(INKS / "inks.csv"), "-o", "x.toml"], "missing measurement"),
        (
            ["calibrate", *TABLES, "-o", "x.toml", "--active", "rm82"],
            "--active: 'rm82' but the tables name the active ink 'lce'",
        ),
    ],
)
def test_bad_input_exits_2_with_one_line(tmp_path, capsys, monkeypatch, args, fragment) -> None:
    monkeypatch.chdir(tmp_path)
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and fragment in err, err
    assert not (tmp_path / "x.toml").exists()


def test_bad_table_names_file_row_and_column(tmp_path, capsys) -> None:
    bad = tmp_path / "bad.csv"
    text = (INKS / "inks.csv").read_text("utf-8").replace(",2.55,MPa,", ",0,MPa,")
    bad.write_text(text, encoding="utf-8")
    assert main(["calibrate", str(bad), "-o", str(tmp_path / "x.toml")]) == 2
    err = capsys.readouterr().err
    assert f"{bad}: row 6, column spread: must be the measurement's standard deviation" in err


def test_an_existing_file_needs_force(calibrated, capsys) -> None:
    assert main(["calibrate", *TABLES, "-o", str(calibrated)]) == 2
    assert "use --force" in capsys.readouterr().err


def test_lattice_rows_are_predicted_by_a_contact_resolved_ramp(tmp_path) -> None:
    from rotomorph.simulate.ink_calibration import calibrate_files

    lattice = tmp_path / "lattice.csv"
    lattice.write_text(
        "quantity,condition,x,x_unit,value,spread,unit,source\n"
        "lattice_area,pattern=expanding; n=3; l=5 mm; A=1.25 mm; v=3 mm/s; layers=1; "
        "ghost_nodes=4,,,99,11,%,a small test lattice\n",
        encoding="utf-8",
    )
    tables = [INKS / "filaments.csv", INKS / "inks.csv", lattice]
    run = calibrate_files(tables, tmp_path / "inks.toml", figures=False)
    (row,) = run.validation
    assert row.predicted is not None and 0.0 < row.predicted < 200.0  # an expanding lattice
    assert "contact-resolved" in row.how
    skipped = calibrate_files(tables, tmp_path / "skip.toml", lattices=False, figures=False)
    assert skipped.validation[0].predicted is None


@pytest.mark.parametrize("char", ["\x1b", "\u202e", "\x9b", "\u2028", "\x07"])
def test_control_characters_in_a_table_never_reach_the_terminal(tmp_path, capsys, char) -> None:
    bad = tmp_path / "bad.csv"
    text = (INKS / "inks.csv").read_text("utf-8").replace("(polydomain)", f"(poly{char}[2J)", 1)
    bad.write_text(text, encoding="utf-8")
    assert main(["calibrate", str(bad), "-o", str(tmp_path / "x.toml")]) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and captured.out == "", captured
    assert f"{bad}: row 6, column source: holds U+{ord(char):04X}" in captured.err
    assert char not in captured.err and captured.err[:-1].isprintable()
    assert not (tmp_path / "x.toml").exists()


@pytest.mark.parametrize("char", ["\x1b", "\u202e", "\n", "\r"])
def test_control_characters_in_a_materials_file_never_reach_the_terminal(
    tmp_path, capsys, char
) -> None:
    bad = tmp_path / "bad.toml"
    escaped = char.encode("unicode_escape").decode("ascii").replace("\\x", "\\u00")
    text = (
        (INKS / "inks.toml").read_text("utf-8").replace('source = "', f'source = "x{escaped}[2J', 1)
    )
    bad.write_text(text, encoding="utf-8")
    assert main(["validate", str(bad)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "must not hold control" in err, err
    assert char not in err[:-1] and err[:-1].isprintable()
