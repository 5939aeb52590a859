"""The lattices-vs-paper example: predictions from the print program, the paper's recipe as a
labelled fit."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "lattices_vs_paper.py"


@pytest.mark.slow
def test_example_quick():
    spec = importlib.util.spec_from_file_location("lattices_vs_paper", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.main(quick=True)
    predicted = [r for r in rows if r["model"] == "print program"]
    recipe = [r for r in rows if r["model"] == "paper recipe"]
    # no fit among the predictions; the recipe's one fit is labelled and nothing of it counts
    assert not any(r["calibration"] for r in predicted)
    assert sum(r["calibration"] for r in recipe) == 1
    assert not any(r["counted"] for r in recipe)
    calibrated = next(r for r in recipe if r["calibration"])
    assert calibrated["predicted"] == pytest.approx(1.37, abs=1e-3)
    areas = [
        r
        for r in predicted
        if r["quantity"] == "lattice_area_ratio"
        and r["condition"] in ("expanding lattice", "contracting lattice")
    ]
    assert [r["condition"] for r in areas] == ["expanding lattice", "contracting lattice"]
    # the sinusoid amplitude A/l = 0.25 is the authors' published simulation input, not a
    # value chosen with the measured areas in view: a physical state is counted; the quick
    # mode's contracting lattice, solved without contact, passes through itself: flagged, not
    # counted
    assert areas[0]["counted"] and areas[0]["physical"] and not areas[0].get("informed_by")
    assert not areas[1]["physical"] and not areas[1]["counted"]
    assert all(isinstance(r["converged"], bool) for r in predicted)
    assert areas[0]["predicted"] > 1.0 > areas[1]["predicted"]
    # the 3 x 3 quick lattices are too small for a curvature sign; the recipe's are exact
    signs = [r for r in recipe if r["quantity"] == "Gaussian curvature sign"]
    assert [r["predicted"] for r in signs] == [1, -1]
