"""The Fig. 5 example (small default): the filter lets 5 mm spheres through only when hot,
the gripper holds every rod when hot and releases them when cooled, nothing interpenetrates."""

from __future__ import annotations

import json
import runpy
from pathlib import Path

import pytest

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "fig5_filter_gripper.py"


def test_fig5_example(capsys):
    module = runpy.run_path(str(EXAMPLE))
    assert module["main"]([]) == 0
    rows = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    filt = [r for r in rows if r["study"] == "filter"]
    (spheres,) = [r for r in rows if r["study"] == "filter_spheres"]
    grip = [r for r in rows if r["study"] == "gripper"]
    (geometry,) = [r for r in rows if r["study"] == "gripper_geometry"]

    assert all(r["stable"] for r in filt + grip)
    # the printed stacks' layers never pass through each other (the gripper's rest on the rods
    # layer by layer)
    assert all(r["admissible"] for r in filt + grip)
    assert filt[0]["opening_min_mm"] < 5.0 < filt[-1]["opening_min_mm"]
    assert spheres["sphere_5mm"].startswith("caught below, passes from")
    assert spheres["sphere_3mm"].startswith("passes already")
    assert spheres["sphere_6mm"] == "caught at every temperature"

    hot = [r for r in grip if r["phase"] == "heating"][-1]
    released = grip[-1]
    assert hot["temperature_C"] == 175.0 and released["temperature_C"] == 50.0
    forces = hot["rod_forces_N"]
    assert min(forces) > 1e-3  # every rod held (N)
    # the print programs (line directions, nozzle turns) leave one mirror symmetry: rods
    # 0 and 3, 1 and 2 alike; the two pairs within a factor of 2
    assert forces[0] == pytest.approx(forces[3], rel=1e-6)
    assert forces[1] == pytest.approx(forces[2], rel=1e-6)
    assert max(forces) < 2.0 * min(forces)
    assert max(released["rod_forces_N"]) < 1e-6  # released on cooling (barrier tail only)
    assert all(r["clearance"] >= 0.999 for r in grip if r["clearance"] is not None)
    assert geometry["minimum_spacing_mm"] < 7.0  # the assumed spacing admits the rods
