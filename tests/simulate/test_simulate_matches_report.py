"""``simulate`` on the example sinusoid design gives the report's numbers for that design."""

from __future__ import annotations

from pathlib import Path

import pytest

from rotomorph.io.designfile import load_design
from rotomorph.simulate.design import simulate_design
from rotomorph.simulate.validation import (
    FILAMENT_SPACINGS,
    SINUSOID_DESIGN,
    sinusoid_ratio,
    validate_filaments,
)

FLIP = SINUSOID_DESIGN["flip_length"]

DESIGN = Path(__file__).resolve().parents[2] / "examples" / "designs" / "sinusoids.toml"


@pytest.mark.slow
def test_simulate_sinusoids_equal_the_report() -> None:
    val = validate_filaments()
    spacing = 0.2  # coarse for speed: the same pipeline at any spacing
    sim = simulate_design(load_design(DESIGN), steps=4, model=val.model, spacing=spacing)
    runs = list(sim.filaments)
    assert len(runs) == 2
    for run, side in zip(runs, ("outer", "inner"), strict=True):
        expected = sinusoid_ratio(side, val.model, spacing, FLIP)
        assert run.final_ratio == pytest.approx(expected, abs=1e-5)
    # and the report's printable-design row is the same construction at its own spacing
    rows = {r["condition"]: r for r in val.rows if r["quantity"] == "sinusoid_end_to_end_ratio"}
    row = rows["active outer (expanding), printable 0.5 mm flips"]
    fine = sinusoid_ratio("outer", val.model, FILAMENT_SPACINGS[1], FLIP)
    assert row["predicted"] == pytest.approx(fine, abs=1e-5)
