"""The lattices-vs-paper example runs and keeps its calibration honest."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "lattices_vs_paper.py"


def test_example_quick():
    spec = importlib.util.spec_from_file_location("lattices_vs_paper", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    rows = module.main(quick=True)
    assert sum(r["calibration"] for r in rows) == 1
    calibrated = next(r for r in rows if r["calibration"])
    assert calibrated["predicted"] == pytest.approx(1.37, abs=1e-3)
    expanding = next(r for r in rows if r["condition"] == "expanding lattice")
    assert abs(expanding["error"]) <= 2 * expanding["spread"]
    contracting = next(r for r in rows if r["condition"] == "contracting lattice")
    assert "contact" in contracting["note"]
    signs = [r for r in rows if r["quantity"] == "Gaussian curvature sign"]
    assert [r["predicted"] for r in signs] == [1, -1]
