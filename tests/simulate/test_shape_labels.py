"""Shape labels in a run's summary name what the filament looks like: a straightened sinusoid
is not called a coil because a helix of huge radius fits a sliver of it."""

from __future__ import annotations

from rotomorph.io.designfile import parse_design
from rotomorph.simulate.design import HELIX_MIN_TURNS, simulate_design

DESIGN = {
    "schema_version": 1,
    "filaments": [
        {
            "name": "expanding",
            "active_side": "outer",
            "flip_length": 0.5,
            "spacing": 0.1,
            "segments": [{"kind": "sinusoid", "amplitude": 1.25, "wavelength": 5.0, "periods": 4}],
        },
        {
            "name": "janus",
            "rotation": 0.0,
            "spacing": 0.25,
            "start": [0.0, 10.0, 0.0],
            "segments": [{"kind": "line", "length": 8.0}],
        },
    ],
}


def test_a_straightened_sinusoid_is_not_labelled_a_coil():
    # before: "expanding: L/L0 = 1.287 (coil)" on the command line, with a fitted helix of
    # 70 mm radius and 0.06 turn in summary.json
    sim = simulate_design(parse_design(DESIGN), steps=2)
    expanding, janus = sim.metadata["filaments"]
    assert expanding["end_to_end_ratio"] > 1.2  # it straightened
    assert expanding["morphology"] is None and "helix" not in expanding
    rejected = expanding["helix_fit_rejected"]
    assert rejected["turns"] < HELIX_MIN_TURNS
    assert "not a helix or coil" in rejected["reason"]
    # a Janus filament bent into most of a ring keeps its label and fit
    assert janus["morphology"] == "coil" and janus["helix"]["turns"] > HELIX_MIN_TURNS
