"""``simulate_design(on_step=...)`` streams each converged step as it is reached: the same
states the finished run holds, in order, the printed state first (what ``rotomorph serve``
draws while a simulation runs)."""

from __future__ import annotations

import numpy as np

from rotomorph.io.designfile import parse_design
from rotomorph.simulate.design import StepReport, simulate_design


def _filaments():
    return parse_design(
        {
            "schema_version": 1,
            "filaments": [
                {
                    "rotation_number": 0.25,
                    "spacing": 1.0,
                    "start": [0.0, 5.0 * i, 0.0],
                    "segments": [{"kind": "line", "length": 8.0}],
                }
                for i in range(2)
            ],
        }
    )


def test_filaments_stream_every_step_of_every_filament_as_the_run_holds_it():
    seen: list[StepReport] = []
    sim = simulate_design(_filaments(), steps=3, on_step=seen.append)
    assert [(r.unit, r.step) for r in seen] == [(u, k) for u in (0, 1) for k in range(4)]
    assert all(r.units == 2 and r.steps == 3 and r.ramp == "temperature" for r in seen)
    for u, fil in enumerate(sim.filaments):
        got = [r for r in seen if r.unit == u]
        assert np.allclose([r.value for r in got], fil.temperature)
        assert [r.stable for r in got] == list(fil.stable)
        for r, expected in zip(got, fil.positions, strict=True):
            np.testing.assert_allclose(r.positions, expected, atol=1e-12)
    assert seen[0].residual == 0.0 and seen[0].stable is True  # the printed state
    assert all(r.residual < 1e-6 for r in seen)


def test_a_lattice_streams_its_ramp_in_the_lab_frame():
    design = parse_design(
        {
            "schema_version": 1,
            "lattice": {
                "n": 3,
                "spacing": 5.0,
                "amplitude": 1.0,
                "pattern": "dome",
                "ghost_nodes": 4,
                "origin": [10.0, 20.0, 0.0],
            },
        }
    )
    seen: list[StepReport] = []
    sim = simulate_design(design, steps=2, on_step=seen.append)
    assert [r.step for r in seen] == [0, 1, 2]
    assert all(r.unit == 0 and r.units == 1 for r in seen)
    ramp = seen[0].ramp
    assert ramp in ("temperature", "actuation")
    np.testing.assert_allclose([r.value for r in seen], sim.scalars[ramp])
    for r, expected in zip(seen, sim.positions, strict=True):
        np.testing.assert_allclose(r.positions, expected, atol=1e-12)
    assert np.allclose(seen[0].positions[:, :2].min(axis=0), [10.0, 20.0], atol=1.01)  # corner
