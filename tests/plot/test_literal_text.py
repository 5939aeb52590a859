"""Names are never parsed as matplotlib mathtext (``$x^{$`` draws as five characters), and a
figure that fails to draw never costs a computed run: results, summary and ParaView files are
kept and the command says how to draw the figures again."""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest
import tomli_w
from matplotlib.figure import Figure

from rotomorph.cli import EXIT_OK, main
from rotomorph.plot.figure import figure_to_rgb, new_figure, save_figure
from rotomorph.sweep import parse_sweep, run_sweep
from rotomorph.sweep.figures import plot_sweep

MATH = ["$x^{$", r"$\frac{1}{0$", "$$", r"a\$b $\alpha$"]


@pytest.mark.parametrize("text", MATH)
def test_new_figures_draw_dollar_signs_literally(tmp_path, text):
    fig = new_figure(3, 2)
    ax = fig.add_subplot()
    ax.plot([0, 1], [0, 1], label=text)
    ax.set_title(text)
    ax.legend()
    figure_to_rgb(fig)  # would raise ValueError in the mathtext parser
    fig.savefig(tmp_path / "direct.png")  # any draw, not only save_figure
    assert all(not t.get_parse_math() for t in [*fig.texts, ax.title])
    plain = Figure()  # a figure not made by new_figure, saved through save_figure
    plain.add_subplot().set_xlabel(text)
    save_figure(plain, tmp_path / "plain.png")


@pytest.fixture(scope="module")
def design(tmp_path_factory):
    doc = {
        "schema_version": 1,
        "name": "$x^{$",
        "filaments": [
            {
                "name": name,
                "rotation_number": 0.25,
                "spacing": 0.5,
                "start": [0.0, 6.0 * i, 0.0],
                "segments": [{"kind": "line", "length": 6.0}],
            }
            for i, name in enumerate(MATH[:2])
        ],
    }
    path = tmp_path_factory.mktemp("math") / "math.toml"
    path.write_text(tomli_w.dumps(doc), encoding="utf-8")
    return path


def test_simulate_and_plot_draw_mathtext_names(design, tmp_path, capsys):
    run = tmp_path / "run"
    assert main(["simulate", str(design), "-o", str(run), "--steps", "2"]) == EXIT_OK
    assert "WARNING" not in capsys.readouterr().err
    names = {p.name for p in (run / "figures").iterdir()}
    assert {"shapes.png", "ramp.png", "end_to_end_ratio.png"} <= names
    assert main(["plot", str(run), "-o", str(tmp_path / "again"), "--no-movie"]) == EXIT_OK
    assert (tmp_path / "again" / "shapes.png").is_file()


def test_figures_that_fail_keep_the_computed_run(design, tmp_path, caplog, monkeypatch):
    import rotomorph.simulate.outputs as outputs

    def broken(*args, **kwargs):
        raise RuntimeError("renderer exploded\nsecond line")

    monkeypatch.setattr(outputs, "plot_run", broken)
    run = tmp_path / "run"
    assert main(["simulate", str(design), "-o", str(run), "--steps", "2"]) == EXIT_OK
    warning = [r.getMessage() for r in caplog.records if "figures not drawn" in r.getMessage()]
    assert len(warning) == 1 and "renderer exploded second line" in warning[0]
    assert "rotomorph plot" in warning[0]
    assert (run / "results.h5").is_file() and (run / "paraview").is_dir()
    summary = json.loads((run / "summary.json").read_text())
    assert summary["n_steps"] == 3


def test_sweep_figures_draw_mathtext_columns(tmp_path):
    sweep = parse_sweep(
        {
            "schema_version": 1,
            "design": {
                "schema_version": 1,
                "filaments": [{"spacing": 0.5, "segments": [{"kind": "line", "length": 8.0}]}],
            },
            "outputs": ["end_to_end_ratio", "curvature"],
            "settings": {"method": "closed_form"},
            "parameters": [
                {"path": "filaments[0].rotation_number", "name": "$x^{$", "values": [0.1, 1.0]},
                {"path": "filaments[0].speed", "name": "$v$ (mm/s", "values": [1.0, 3.0]},
            ],
        }
    )
    with ThreadPoolExecutor(2) as pool:
        result = run_sweep(sweep, tmp_path / "out", executor=pool, fsync=False)
    paths = plot_sweep(result.table, ["$x^{$", "$v$ (mm/s"], sweep.outputs, tmp_path / "figs")
    assert len(paths) == 2 and all(p.stat().st_size > 1000 for p in paths)
    one = plot_sweep(result.table, ["$x^{$"], sweep.outputs, tmp_path / "one")
    assert [p.name for p in one] == ["curve.png"]
    assert np.isfinite(result.table.column("end_to_end_ratio").to_numpy()).all()
