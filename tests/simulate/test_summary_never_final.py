"""No output of a run calls its last state "final": it is the end of the ramp, reported with
its converged / stable / clearance checks (summary.json ``end_of_ramp``) and the verdict."""

from __future__ import annotations

import json

from rotomorph.io.designfile import parse_design
from rotomorph.io.results import summarize
from rotomorph.simulate.design import simulate_design
from rotomorph.simulate.run_data import describe_run


def _keys(node):
    if isinstance(node, dict):
        for key, value in node.items():
            yield key
            yield from _keys(value)
    elif isinstance(node, list):
        for value in node:
            yield from _keys(value)


def test_a_lattice_summary_has_no_final_block_without_its_checks():
    # before: metadata.final of a lattice run repeated the end-of-ramp scalars without
    # converged, stable or the verdict, under the name the outputs promise never to use
    design = parse_design({"schema_version": 1, "lattice": {"n": 3, "ghost_nodes": 3, "layers": 1}})
    summary = summarize(describe_run(simulate_design(design, steps=1)))
    assert "final" not in set(_keys(summary))
    end = summary["end_of_ramp"]
    assert {"converged", "stable", "min_clearance", "area_ratio"} <= set(end)
    # converged, certified stable, clear: "yes" (this accepted any verdict)
    assert summary["physical"]["verdict"] == "yes" and end["stable"] == 1.0
    json.dumps(summary, allow_nan=False)


def test_the_api_takes_a_model_by_name_and_refuses_anything_else():
    # before: rotomorph.simulate(design, model="calibrated") raised AttributeError
    # ('str' object has no attribute 'transition_width') from inside the materials model
    import pytest

    import rotomorph
    from rotomorph.errors import InvalidParameterError

    design = parse_design(
        {
            "schema_version": 1,
            "filaments": [{"spacing": 1.0, "segments": [{"kind": "line", "length": 6.0}]}],
        }
    )
    named = rotomorph.simulate(design, steps=1, model="warner-terentjev")
    default = rotomorph.simulate(design, steps=1, model=None)
    assert named.positions.shape == default.positions.shape
    assert rotomorph.predict(design, model="room-temperature")[0].curvature >= 0.0
    for bad in ("calibrat", 3):
        with pytest.raises(InvalidParameterError, match="model"):
            rotomorph.simulate(design, steps=1, model=bad)
