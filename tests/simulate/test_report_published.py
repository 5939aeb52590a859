"""The report's section on the authors' Fig. 4 simulation: its record, figures and text say what
the sweeps computed (quick grid)."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest

from rotomorph.lattice.published import LOGGED_RUN_SECONDS, SPACING, PublishedSweep
from rotomorph.simulate.report_published import not_physical, published_section


def test_a_value_is_physical_only_if_stable_and_admissible():
    sweep = SimpleNamespace(
        stretch=np.array([-0.1, 0.0, 0.1, 0.2]),
        stable=(True, True, False, True),
        stack_overlaps=np.array([0, 3, 0, 0]),
    )
    assert [not_physical(sweep, k) for k in range(4)] == [  # type: ignore[arg-type]
        None,
        "3 segment pairs interpenetrate",
        "not certified stable",
        None,
    ]
    assert PublishedSweep.physical.fget(sweep) == (True, False, False, True)  # type: ignore[attr-defined]
    unchecked = SimpleNamespace(stretch=np.zeros(1), stable=(True,), stack_overlaps=None)
    assert not_physical(unchecked, 0) == "admissibility not checked"  # type: ignore[arg-type]
    assert PublishedSweep.physical.fget(unchecked) == (False,)  # type: ignore[attr-defined]


@pytest.mark.slow
def test_section_record_figures_and_text(tmp_path):
    figs = tmp_path / "figures"
    figs.mkdir()
    section = published_section(tmp_path, figs, quick=True)
    record = json.loads((tmp_path / "published_fig4_sweep.json").read_text())
    assert record["authors_logged_run_s"] == LOGGED_RUN_SECONDS
    rows = record["rows"]
    assert len(rows) == 2 * len(section.on_floor.stretch) == 22
    floor = [r for r in rows if r["case"] == "on_floor"]
    np.testing.assert_allclose(
        [r["characteristic_curvature_times_l"] for r in floor],
        section.on_floor.characteristic_curvature * SPACING,
    )
    assert {p.name for p in section.figures} == {
        "published_fig4_sweep.png",
        "published_fig4_shapes.png",
    }
    text = "\n".join(section.lines)
    assert "limbs 29 and 30 are in neither list" in text
    first = section.on_floor.first(-1)
    assert f"first saddle at stretch {first:+.2f}" in text
    # -0.17 is not on the quick grid: the section says so instead of describing a neighbour
    assert "not on this sweep's grid" in text
    for p in section.figures:
        assert f"](figures/{p.name})" in text
    # every state is checked for interpenetrating filaments, and the record says so per row
    assert section.on_floor.stack_overlaps is not None
    assert [r["stack_overlaps"] for r in floor] == [int(c) for c in section.on_floor.stack_overlaps]
    assert [r["physical"] for r in floor] == list(section.on_floor.physical)
    assert "Physical states (on the floor)" in text or "NOT PHYSICAL (on the floor)" in text
