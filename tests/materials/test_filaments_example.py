"""The example script runs and reports every required row."""

from __future__ import annotations

import importlib.util
import io
import json
from contextlib import redirect_stdout
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "filaments_vs_paper.py"


def _load():
    spec = importlib.util.spec_from_file_location("filaments_vs_paper", EXAMPLE)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_example_rows_and_json_lines() -> None:
    mod = _load()
    buf = io.StringIO()
    with redirect_stdout(buf):
        assert mod.main([]) == 0
    lines = [json.loads(line) for line in buf.getvalue().splitlines()]
    assert lines == mod.rows()
    keys = {"quantity", "condition", "measured", "spread", "predicted", "calibration"}
    assert all(keys <= set(r) for r in lines)
    curv = [r for r in lines if r["quantity"].startswith("janus_curvature")]
    assert len(curv) == 8
    for model in ("warner_terentjev", "empirical_threshold"):
        rows = [r for r in curv if r["model"] == model]
        assert 1 <= sum(r["calibration"] for r in rows) <= 2
    pure = [r for r in lines if r["quantity"].startswith("pure_lce")]
    assert [r["condition"] for r in pure] == ["omega*=0.06", "omega*=0.25", "omega*=1", "omega*=2"]
    comp = [r for r in lines if r["quantity"].startswith("composite")]
    assert [r["shape"] for r in comp] == ["coil", "helix"]
    assert abs(comp[1]["predicted"] - comp[1]["measured"]) < 2 * comp[1]["spread"]
