"""The rod basics example runs and its helix matches the exact one."""

from __future__ import annotations

import json
import runpy
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "rod_basics.py"


def test_rod_basics_example(capsys):
    module = runpy.run_path(str(EXAMPLE))
    assert module["main"](["--nodes", "61"]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    helix, cantilever = rows
    assert helix["radius"] == pytest.approx(helix["radius_exact"], rel=1e-2)
    assert helix["pitch"] == pytest.approx(helix["pitch_exact"], rel=1e-2)
    assert 0 < cantilever["tip_deflection_mm"] < 20
