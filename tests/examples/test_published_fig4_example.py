"""The authors' Fig. 4 example runs (quick mode): their small weight delays the lift-off past
the weightless buckling, every state is certified stable, the figures are drawn."""

from __future__ import annotations

import json
import runpy
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "published_fig4.py"


#: The weightless sweep's arguments, as the example and the report pass them.
WEIGHTLESS = {"floor": False, "friction": 0.0, "acceleration": 0.0}


def _shared_with_the_report(step: float, end: float, **kw: object) -> object:
    """``published_sweep``, read from the run's result cache where the call is one of the
    report section's quick sweeps (the same arguments, so the same result): the suite computes
    them once for this example, the section's test and ``rotomorph paper --quick``."""
    from rotomorph.lattice.published import published_sweep
    from rotomorph.simulate.report_published import GRID, report_sweeps

    if (step, end) == GRID[True] and kw in ({}, WEIGHTLESS):
        floor, free = report_sweeps(quick=True)
        return free if kw else floor
    return published_sweep(step, end, **kw)  # type: ignore[arg-type]


@pytest.mark.slow
def test_published_fig4_example_quick(tmp_path, capsys):
    module = runpy.run_path(str(EXAMPLE))
    module["main"].__globals__["published_sweep"] = _shared_with_the_report
    assert module["main"](["--quick", "-o", str(tmp_path)]) == 0
    lines = [json.loads(line) for line in capsys.readouterr().out.splitlines()]
    total = lines[-1]
    rows = {(r["case"], r["stretch"]): r for r in lines[:-1]}
    assert total["case"] == "total" and total["values"] == 11 and len(rows) == 22
    assert all(r["stable"] is True for r in rows.values())
    floor = {s: rows["on_floor", s] for c, s in rows if c == "on_floor"}
    free = {s: rows["weightless", s] for c, s in rows if c == "weightless"}
    # negative stretch: saddles; positive: domes (their README: "positive -> sphere")
    assert floor[-0.25]["gaussian_sign"] == -1 and floor[0.25]["gaussian_sign"] == 1
    assert free[-0.25]["gaussian_sign"] == -1 and free[0.25]["gaussian_sign"] == 1
    # the weight holds the buckled lattice on the floor: flat where the free one has buckled
    assert free[-0.1]["gaussian_sign"] == -1 and floor[-0.1]["gaussian_sign"] == 0
    assert floor[-0.1]["floor_lift_mm"] < 2.0  # no node a diameter above its printed height
    assert abs(total["first_saddle"]) > abs(total["first_saddle_weightless"])
    assert abs(total["first_dome"]) >= abs(total["first_dome_weightless"])
    for name in ("published_fig4_sweep.png", "published_fig4_shapes.png"):
        img = np.asarray(Image.open(tmp_path / name).convert("L"), dtype=float)
        assert img.std() > 5.0, f"{name} looks blank"
