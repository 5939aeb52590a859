"""The ``rotomorph`` command line through ``main(argv)``: exit codes, messages, outputs."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from rotomorph.cli import EXIT_FAILED, EXIT_OK, EXIT_USAGE, main
from rotomorph.io.results import read_results

DESIGNS = sorted((Path(__file__).parents[2] / "examples" / "designs").glob("*.toml"))

FILAMENT = """schema_version = 1
name = "one"
[[filaments]]
name = "w*=0.25"
speed = {speed}
rotation_number = 0.25
active_fraction = {fraction}
active_material = "{material}"
spacing = 0.25
segments = [{{ kind = "line", length = 10.0 }}]
"""


def _design(tmp_path: Path, speed="3.0", fraction="0.5", material="lce") -> Path:
    p = tmp_path / "design.toml"
    p.write_text(FILAMENT.format(speed=speed, fraction=fraction, material=material))
    return p


def _one_line_error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err, err
    assert err.startswith("rotomorph: error: "), err
    return err


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if ".tmp-" in p.name or ".old-" in p.name)


def _non_blank_png(path: Path, min_bytes: int = 5_000) -> None:
    assert path.stat().st_size > min_bytes, path
    img = np.asarray(Image.open(path).convert("L"), dtype=float)
    assert img.std() > 5.0, f"{path} looks blank"


def test_help_everywhere(capsys):
    for argv in (
        ["--help"],
        *[[c, "--help"] for c in ("validate", "gcode", "simulate", "plot", "paper")],
    ):
        assert main(argv) == EXIT_OK
        assert "usage:" in capsys.readouterr().out


def test_no_command_and_unknown_option(capsys):
    assert main([]) == EXIT_USAGE
    assert "usage:" in capsys.readouterr().err
    assert main(["simulate", "--bogus"]) == EXIT_USAGE
    _one_line_error(capsys)


@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_validate_every_example(design, capsys):
    assert main(["validate", str(design)]) == EXIT_OK
    assert "valid design" in capsys.readouterr().out


@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
@pytest.mark.parametrize("dialect", ["aerotech", "rs274", "marlin"])
def test_gcode_every_example(design, dialect, tmp_path):
    out = tmp_path / "part.gcode"
    assert main(["gcode", str(design), "-o", str(out), "--dialect", dialect]) == EXIT_OK
    text = out.read_text()
    assert "G1" in text and len(text.splitlines()) > 20
    assert _leftovers(tmp_path) == []


def test_gcode_machine_profile_and_limits(tmp_path, capsys):
    machine = tmp_path / "machine.toml"
    machine.write_text(
        '[machine]\nname = "tiny"\ndialect = "rs274"\nenvelope_max = [5.0, 5.0, 5.0]\n'
    )
    out = tmp_path / "part.gcode"
    code = main(["gcode", str(DESIGNS[0]), "-o", str(out), "--machine", str(machine)])
    assert code == EXIT_USAGE
    err = _one_line_error(capsys)
    assert "machine limits" in err and "machine profile key 'envelope_max'" in err
    assert not out.exists() and _leftovers(tmp_path) == []


def test_schema(capsys):
    assert main(["validate", "--schema"]) == EXIT_OK
    schema = json.loads(capsys.readouterr().out)
    assert "filaments" in schema["properties"]


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"speed": "-2.0"}, "filaments[0].speed"),
        ({"speed": '"fast"'}, "filaments[0].speed"),
        ({"fraction": "1.5"}, "filaments[0].active_fraction"),
        ({"material": "unobtainium"}, "unobtainium"),
    ],
)
def test_bad_design_names_the_field(tmp_path, capsys, kwargs, field):
    design = _design(tmp_path, **kwargs)
    out = tmp_path / "out"
    cmds = (["validate", str(design)], ["simulate", str(design), "-o", str(out)])
    for argv in cmds:
        code = main(argv)
        assert code == EXIT_USAGE, argv
        assert field in _one_line_error(capsys)
    assert not out.exists()
    assert _leftovers(tmp_path) == []


def test_missing_empty_and_invalid_files(tmp_path, capsys):
    assert main(["validate", str(tmp_path / "nope.toml")]) == EXIT_USAGE
    assert "no such file" in _one_line_error(capsys)
    assert main(["validate", ""]) == EXIT_USAGE
    assert "empty path" in _one_line_error(capsys)
    bad = tmp_path / "bad.toml"
    bad.write_text("schema_version = 1\n[[filaments]\n")
    assert main(["validate", str(bad)]) == EXIT_USAGE
    assert "not valid TOML" in _one_line_error(capsys)
    assert main(["simulate", str(_design(tmp_path)), "-o", ""]) == EXIT_USAGE
    assert "empty path" in _one_line_error(capsys)
    assert main(["plot", str(bad), "-o", str(tmp_path / "p")]) == EXIT_USAGE
    _one_line_error(capsys)


@pytest.mark.slow
def test_simulate_filament_writes_everything(tmp_path, capsys):
    out = tmp_path / "runs" / "run"  # the parent folder is created as needed
    code = main(["simulate", str(_design(tmp_path)), "-o", str(out), "--steps", "3"])
    assert code == EXIT_OK, capsys.readouterr().err
    assert "L/L0" in capsys.readouterr().out
    res = read_results(out / "results.h5")
    assert res.n_steps == 4 and res.positions.shape[2] == 3
    assert res.scalars["end_to_end_ratio"][-1] < 0.95  # the composite coils
    # the stored Janus side: printed, the program's interface normals; coiled, the active half
    # (which contracts more) faces the centre of curvature
    from rotomorph.design.program import PrintProgram

    (prog,) = res.programs
    printed = PrintProgram(points=prog["points"], speed=prog["speed"],
                           nozzle_angle=prog["nozzle_angle"], radius=prog["radius"])  # fmt: skip
    np.testing.assert_allclose(res.fields["active_normal"][0], printed.interface_normals, atol=1e-9)
    p, n = res.positions[-1], res.fields["active_normal"][-1]
    towards = p[:-2] + p[2:] - 2 * p[1:-1]
    both = n[:-1] + n[1:]
    cos = np.einsum("ij,ij->i", towards, both) / (
        np.linalg.norm(towards, axis=1) * np.linalg.norm(both, axis=1)
    )
    assert np.median(cos) > 0.95
    assert res.units["twist"] == "1/mm" and res.static["arc_length"][-1] == pytest.approx(10.0)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["n_steps"] == 4
    assert summary["end_of_ramp"]["end_to_end_ratio"] == pytest.approx(
        res.scalars["end_to_end_ratio"][-1]
    )
    # every step converged, certified stable and clear of itself (the old check accepted any
    # of "yes", "unknown" and "no")
    assert summary["physical"]["verdict"] == "yes"
    assert summary["physical"]["reason"] == "all checks passed"
    assert summary["filaments"][0]["name"] == "w*=0.25"
    for png in ("shapes.png", "ramp.png", "end_to_end_ratio.png"):
        _non_blank_png(out / "figures" / png)
    movie = next((out / "figures").glob("morphing.*"))
    assert movie.suffix in (".mp4", ".gif") and movie.stat().st_size > 10_000
    pvd = (out / "paraview" / "morphing.pvd").read_text()
    assert pvd.count("<DataSet") == 4
    assert len(list((out / "paraview").glob("morphing_*.vtp"))) == 4
    assert len(list((out / "paraview").glob("janus_*.vtp"))) == 4  # the Janus tube surfaces
    assert (out / "paraview" / "show_janus.py").is_file()
    assert _leftovers(out.parent) == []
    # refuses to overwrite, then --force replaces
    assert main(["simulate", str(_design(tmp_path)), "-o", str(out), "--steps", "2"]) == EXIT_USAGE
    assert "--force" in _one_line_error(capsys)
    assert (
        main(
            [
                "simulate",
                str(_design(tmp_path)),
                "-o",
                str(out),
                "--steps",
                "2",
                "--force",
                "--no-movie",
            ]
        )
        == EXIT_OK
    )
    assert read_results(out / "results.h5").n_steps == 3
    assert not list((out / "figures").glob("morphing.*"))
    assert _leftovers(out.parent) == []
    # plot re-creates the figures from the HDF5 file, into the run's own figures/ folder
    # (the README's layout: no figures/figures nesting, no --force needed)
    figs = out / "figures"
    before = sorted(p.name for p in figs.iterdir())
    code = main(["plot", str(out / "results.h5"), "-o", str(figs), "--no-movie"])
    assert code == EXIT_OK, capsys.readouterr().err
    assert sorted(p.name for p in figs.iterdir()) == before
    assert not (figs / "figures").exists()
    _non_blank_png(figs / "shapes.png")
    # a new nested folder is created as needed
    assert main(["plot", str(out), "-o", str(tmp_path / "a" / "b"), "--no-movie"]) == EXIT_OK
    _non_blank_png(tmp_path / "a" / "b" / "shapes.png")


def test_simulate_failure_leaves_nothing(tmp_path, capsys, monkeypatch):
    import rotomorph.simulate.design as sd
    from rotomorph.errors import ConvergenceError

    def boom(*args, **kwargs):
        raise ConvergenceError("static solve did not converge: test")

    monkeypatch.setattr(sd, "simulate_filament", boom)
    out = tmp_path / "run"
    assert main(["simulate", str(_design(tmp_path)), "-o", str(out)]) == EXIT_FAILED
    assert "did not converge" in _one_line_error(capsys)
    assert not out.exists() and _leftovers(tmp_path) == []


@pytest.mark.slow
def test_simulate_lattice(tmp_path, capsys):
    pytest.importorskip(
        "rotomorph.lattice.heating", reason="lattice heating module not written yet"
    )
    design = tmp_path / "lattice.toml"
    text = (DESIGNS[0].parent / "lattice_expanding.toml").read_text()
    design.write_text(text.replace("n = 5", "n = 3").replace("ghost_nodes = 10", "ghost_nodes = 6"))
    out = tmp_path / "run"
    assert main(["simulate", str(design), "-o", str(out), "--steps", "3"]) == EXIT_OK, (
        capsys.readouterr().err
    )
    res = read_results(out / "results.h5")
    assert res.scalars["area_ratio"][-1] > 1.2  # expanding
    assert "relative_curvature_change" in res.fields
    for png in ("shapes.png", "lattice_field.png", "lattice_views.png", "lattice_metrics.png"):
        _non_blank_png(out / "figures" / png)
    assert "active_normal" in res.fields and "lattice_edge" in res.static
    assert (out / "paraview" / "morphing.pvd").exists()
    assert _leftovers(tmp_path) == []


def test_python_dash_m(tmp_path):
    import subprocess
    import sys

    r = subprocess.run([sys.executable, "-m", "rotomorph", "validate", str(DESIGNS[0])],
                       capture_output=True, text=True, check=False)  # fmt: skip
    assert r.returncode == 0 and "valid design" in r.stdout
