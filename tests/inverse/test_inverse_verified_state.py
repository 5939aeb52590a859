"""A curve inverse design reports whether its verifying simulation is physical (stable, no
self-overlap), in summary.json and on the command line, like every other simulated state."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rotomorph.cli import main
from rotomorph.inverse.run import _verified_state

HELIX = (
    'schema_version = 1\nkind = "curve"\n[curve]\nfamily = "helix"\n'
    "radius_start = 2.0\nradius_end = 2.2\npitch = 1.5\nturns = 1.0\n"
)


def test_curve_summary_and_line_carry_the_verified_state(tmp_path, capsys):
    # before: rms_error of the forward simulation without stable or clearance
    target = tmp_path / "helix.toml"
    target.write_text(HELIX, encoding="utf-8")
    assert main(["inverse", str(target), "-o", str(tmp_path / "helix_design.toml")]) == 0
    assert capsys.readouterr().out.rstrip().endswith("; verified state physical")
    summary = json.loads((tmp_path / "helix_design_inverse" / "summary.json").read_text())
    assert summary["stable"] is True
    assert summary["min_clearance_diameters"] >= 1.0
    assert summary["physical"] == {"verdict": "yes", "reason": "all checks passed"}


def test_an_overlapping_or_unstable_verified_shape_is_flagged():
    t = np.linspace(0.0, 4 * np.pi, 400)  # two turns of a ring: passes through itself
    ring = np.c_[3 * np.cos(t), 3 * np.sin(t), 0 * t]
    state = _verified_state(ring, True, radius=0.3)
    assert state["physical"]["verdict"] == "no"
    assert "passes through itself" in state["physical"]["reason"]
    line = np.c_[t, 0 * t, 0 * t]
    assert _verified_state(line, False, 0.3)["physical"]["verdict"] == "no"
    assert _verified_state(line, None, 0.3)["physical"]["verdict"] == "unknown"


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (  # before: "options.spacng: Extra inputs are not permitted"
            HELIX + "[options]\nspacng = 0.1\n",
            "options.spacng: unknown key; remove it or check its spelling",
        ),
        (  # before: "kind: Field required"
            'schema_version = 1\n[[filaments]]\nsegments = [{kind = "line", length = 5.0}]\n',
            "kind: is required: this looks like a design file",
        ),
        (
            'schema_version = 1\n[curve]\nfamily = "helix"\n',
            "kind: is required; add kind = 'curve', 'dome', 'saddle' or 'height_map'",
        ),
    ],
)
def test_target_file_mistakes_say_what_to_do(tmp_path, capsys, text, message):
    target = tmp_path / "target.toml"
    target.write_text(text, encoding="utf-8")
    assert main(["inverse", str(target), "-o", str(tmp_path / "d.toml")]) == 2
    assert capsys.readouterr().err.strip().startswith(f"rotomorph: error: {message}")
