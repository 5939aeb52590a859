"""The stability example runs and matches the elastica, the Euler load and Michell's ring."""

from __future__ import annotations

import json
import runpy
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "stability_modes.py"


def test_stability_modes_example(capsys):
    module = runpy.run_path(str(EXAMPLE))
    assert module["main"](["--nodes", "33"]) == 0
    column, euler, ring = (json.loads(line) for line in capsys.readouterr().out.splitlines())
    assert column["stable"] and column["escapes"] >= 1
    assert column["tip_deflection_over_L"] == pytest.approx(
        column["tip_deflection_over_L_elastica"], abs=3e-3
    )
    assert column["tip_x_over_L"] == pytest.approx(column["tip_x_over_L_elastica"], abs=1e-2)
    assert euler["critical_load_over_euler"] == pytest.approx(1.0, abs=5e-3)
    assert ring["stable_at_0.9"] and not ring["stable_at_1.1"]
    assert ring["lowest_eigenvalue_at_0.9"] > 0 > ring["lowest_eigenvalue_at_1.1"]
    assert ring["mode_out_of_plane_at_1.1"]
