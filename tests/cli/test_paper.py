"""``rotomorph paper --quick``: report, summary rows and figures, read back and re-checked."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest
from PIL import Image

from rotomorph.cli import EXIT_OK, main
from rotomorph.materials import load_table
from rotomorph.materials.calibrate import janus_curvature, paper_calibration

KEYS = {
    "quantity",
    "condition",
    "measured",
    "spread",
    "predicted",
    "predicted_sd",
    "error",
    "calibration",
    "converged",
    "note",
    # the band in parts, the weak-test verdict and the extrapolation flag
    "sd_calibration",
    "sd_nuisance",
    "sd_numerical",
    "sd_model_form",
    "weak_test",
    "extrapolated",
    "extrapolation",
}


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    out = tmp_path_factory.mktemp("paper") / "out"
    assert main(["paper", "-o", str(out), "--quick", "--allow-unconverged"]) == EXIT_OK
    return out


@pytest.mark.slow
def test_summary_rows(report):
    rows = json.loads((report / "summary.json").read_text())
    assert isinstance(rows, list) and rows
    for r in rows:
        assert KEYS <= set(r), r
        if r["measured"] is not None and r["predicted"] is not None:
            assert r["error"] == pytest.approx(r["predicted"] - r["measured"], abs=2e-4)
        parts = [r[k] for k in ("sd_calibration", "sd_nuisance", "sd_numerical", "sd_model_form")]
        if r["weak_test"] is not None and r["predicted_sd"] is not None and r["z"] is not None:
            # the total is the parts' root sum of squares, and z uses it
            total = float(np.sqrt(sum((p or 0.0) ** 2 for p in parts)))
            assert r["predicted_sd"] == pytest.approx(total, abs=2e-5)
            comb = np.hypot(r["spread"], r["predicted_sd"])
            assert r["z"] == pytest.approx(r["error"] / comb, abs=2e-3)
    quantities = {r["quantity"] for r in rows}
    assert {
        "janus_curvature",
        "pure_lce_length_L_over_L0",
        "composite_length_L_over_L0",
        "sinusoid_end_to_end_ratio",
        "lattice_area_ratio",
        "lattice_gaussian_sign",
    } <= quantities


@pytest.mark.slow
def test_numbers_match_the_models(report):
    rows = json.loads((report / "summary.json").read_text())
    # leave-one-group-out: the curvature rows come from the fit without the curvature group
    fit = paper_calibration(exclude=("janus_curvature",)).chosen
    table = load_table("janus_curvature")
    expected = janus_curvature(fit.model, table.x)
    got = [r for r in rows if r["quantity"] == "janus_curvature"]
    assert [r["condition"] for r in got] == list(table.condition)
    np.testing.assert_allclose([r["predicted"] for r in got], expected, atol=2e-3)
    assert not any(r["calibration"] for r in got) and all(r["counted"] for r in got)
    assert not any(r["calibration"] and r["counted"] for r in rows)
    assert sum(r["counted"] for r in rows) >= 10
    # the composite coil at ω* = 0.06 is strongly contracted, the pure LCE rod is not
    comp = next(r for r in rows if r["quantity"] == "composite_length_L_over_L0")
    pure = next(r for r in rows if r["quantity"] == "pure_lce_length_L_over_L0")
    assert comp["predicted"] < 0.4 and 0.7 < pure["predicted"] < 0.95


@pytest.mark.slow
def test_report_and_figures(report):
    md = (report / "report.md").read_text()
    rows = json.loads((report / "summary.json").read_text())
    for r in rows:
        if r["predicted"] is not None:
            assert f"{r['predicted']:.4g}" in md
    figures = re.findall(r"!\[[^\]]*\]\((figures/[^)]+)\)", md)
    assert len(figures) >= 6
    for fig in figures:
        path = report / fig
        assert path.stat().st_size > 10_000, path
        img = np.asarray(Image.open(path).convert("L"), dtype=float)
        assert img.std() > 5.0, f"{fig} looks blank"


@pytest.mark.slow
def test_rerun_into_its_own_folder(report, tmp_path, capsys, monkeypatch):
    """A second ``paper`` into its own output folder replaces it (no --force), with progress
    lines that count computations; a folder holding anything else is refused, naming it."""
    import shutil

    import rotomorph._progress as progress_module

    monkeypatch.setattr(progress_module, "INTERVAL", 0.05)
    monkeypatch.setattr(progress_module, "FIRST_LINE", 0.01)
    out = tmp_path / "out"
    shutil.copytree(report, out)
    capsys.readouterr()
    assert main(["paper", "-o", str(out), "--quick", "--allow-unconverged"]) == EXIT_OK
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.startswith("rotomorph: paper: ")]
    # the plan counted every computation: the closing line has them all done
    assert lines and re.match(r"rotomorph: paper: (\d+) of \1 computations", lines[-1]), err
    assert (out / "report.md").is_file() and (out / "rotomorph-run.json").is_file()
    (out / "notes.txt").write_text("mine", encoding="utf-8")
    assert main(["paper", "-o", str(out), "--quick"]) == 2
    err = capsys.readouterr().err.strip()
    assert "notes.txt" in err and "--force" in err and "\n" not in err
    assert (out / "notes.txt").read_text(encoding="utf-8") == "mine"
