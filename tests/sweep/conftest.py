"""A small sweep shared by the sweep tests: 15 points of short rod filaments, 6 of them invalid."""

from __future__ import annotations

from pathlib import Path

import pytest

SWEEP_TOML = """
schema_version = 1
name = "small"
outputs = ["end_to_end_ratio", "morphology", "curvature", "helix_pitch", "min_clearance"]

[design]
schema_version = 1
[[design.filaments]]
speed = 1.0
rotation_number = 0.25
spacing = 1.0
segments = [{ kind = "line", length = 10.0 }]

[settings]
steps = 2

[machine]
max_feed = 5.0          # mm/s: the 9 mm/s points cannot be printed

[[parameters]]
path = "filaments[0].rotation_number"
values = [0.0, 0.25, 1.0]

[[parameters]]
path = "filaments[0].speed"
values = [0.5, 1.0, 2.0, 9.0, -1.0]
"""


@pytest.fixture(scope="session")
def sweep_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("sweepfile") / "small.toml"
    path.write_text(SWEEP_TOML, encoding="utf-8")
    return path


@pytest.fixture(scope="session")
def local_result(sweep_file, tmp_path_factory):
    """The small sweep on the default local process pool (2 workers)."""
    from rotomorph.sweep import load_sweep, run_sweep

    folder = tmp_path_factory.mktemp("local") / "out"
    return run_sweep(load_sweep(sweep_file), folder, workers=2)


def without_wall_time(table):
    """A table's rows without the one column that differs between executions."""
    return table.drop_columns(["wall_time_s"]).to_pylist()
