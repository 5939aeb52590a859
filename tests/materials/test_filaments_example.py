"""The filament example prints the leave-one-group-out rows of the contract."""

from __future__ import annotations

import importlib.util
import io
import json
from contextlib import redirect_stdout
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "filaments_vs_paper.py"
KEYS = {
    "quantity",
    "condition",
    "measured",
    "spread",
    "predicted",
    "predicted_sd",
    "calibration",
    "converged",
}


def _load():
    spec = importlib.util.spec_from_file_location("filaments_vs_paper", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.slow
def test_example_rows_and_json_lines() -> None:
    mod = _load()
    buf = io.StringIO()
    with redirect_stdout(buf):
        assert mod.main([]) == 0
    rows = [json.loads(line) for line in buf.getvalue().splitlines()]
    summary = mod.summarise(rows)
    assert all(KEYS <= set(r) for r in rows)
    assert all(isinstance(r["converged"], bool) for r in rows)
    # one row per measured filament quantity
    by = {}
    for r in rows:
        by.setdefault(r["quantity"], []).append(r["condition"])
    assert len(by["janus_curvature"]) == 4 and len(by["pure_lce_length_L_over_L0"]) == 4
    assert len(by["composite_length_L_over_L0"]) == 2
    # the counted ideal-flip sinusoids and the printable design shown next to them
    assert len(by["sinusoid_end_to_end_ratio"]) == 4
    sinus = [r for r in rows if r["quantity"] == "sinusoid_end_to_end_ratio"]
    assert [r["counted"] for r in sinus] == [True, True, False, False]
    # fits/inputs are never counted; every counted row is out of sample with an uncertainty
    for r in rows:
        if r["calibration"]:
            assert not r["counted"]
        if r["counted"]:
            assert r["calibrated_without"] and r["predicted_sd"] is not None
    assert summary["out_of_sample_predictions"] == sum(r["counted"] for r in rows) >= 10
