"""``simulate`` says so in every output when a design lies outside the calibrated range."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from rotomorph.cli import EXIT_OK, main
from rotomorph.io.results import read_results

DESIGN = """schema_version = 1
name = "fast"
[[filaments]]
name = "janus"
speed = {speed}
spacing = 0.5
segments = [{{ kind = "line", length = 6.0 }}]
"""


def _run(tmp_path: Path, speed: float, capsys) -> tuple[str, dict, Path]:
    design = tmp_path / f"v{speed:g}.toml"
    design.write_text(DESIGN.format(speed=speed))
    out = tmp_path / f"run{speed:g}"
    code = main(["simulate", str(design), "-o", str(out), "--steps", "2", "--no-movie"])
    assert code == EXIT_OK, capsys.readouterr().err
    line = capsys.readouterr().out
    return line, json.loads((out / "summary.json").read_text()), out


@pytest.mark.slow
def test_a_speed_outside_the_calibrated_range_is_said_everywhere(tmp_path, capsys):
    from rotomorph.simulate.outputs import _state_title, _verdicts

    line, summary, out = _run(tmp_path, 20.0, capsys)
    why = "speed 20 mm/s outside the calibrated 0.25-3 mm/s (extrapolated)"
    assert "EXTRAPOLATED" in line and why in line
    assert summary["extrapolated"] is True and summary["extrapolation"] == [why]
    assert summary["filaments"][0]["extrapolation"] == [why]
    # the results file and every figure title drawn from it
    res = read_results(out / "results.h5")
    assert res.metadata["extrapolation"] == [why]
    title, _ = _state_title(res, res.n_steps - 1, _verdicts(res))
    assert "EXTRAPOLATED: " + why in title
    # inside the range: nothing said
    line, summary, _ = _run(tmp_path, 3.0, capsys)
    assert "EXTRAPOLATED" not in line
    assert summary["extrapolated"] is False and summary["extrapolation"] == []
