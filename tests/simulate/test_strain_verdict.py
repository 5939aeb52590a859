"""An equilibrium whose edges are stretched far beyond the rod model's small-strain law is
flagged as not physical in every output (a dead load that flips a filament and pulls it to
several times its length converges, and is nonsense)."""

from __future__ import annotations

import numpy as np
import pytest

from rotomorph.design.path import Path as PrintPath
from rotomorph.design.program import PrintProgram
from rotomorph.io.results import read_results, summarize, write_results
from rotomorph.io.validity import MAX_AXIAL_STRAIN, assess, run_verdict
from rotomorph.materials.natural import natural_field
from rotomorph.simulate.filament import rod_model, simulate_filament
from rotomorph.simulate.outputs import as_run, run_line
from rotomorph.simulate.run_data import describe_run
from rotomorph.solve.loads import Loads
from rotomorph.solve.static import solve_static


def _program():
    return PrintProgram.from_rotation(PrintPath.line((0, 0, 0), (10, 0, 0), 0.5), 3.0, 0.0)


def _pull(n, force):
    """Equal and opposite forces (N) on the two ends: uniform tension ``force``."""
    return Loads(forces=[(0, (-force, 0.0, 0.0)), (n - 1, (force, 0.0, 0.0))])


def test_the_axial_strain_of_a_pulled_rod_is_force_over_stiffness():
    prog = _program()
    model = rod_model(prog, natural_field(prog, None, 25.0))
    ea = np.asarray(model.axial_stiffness, dtype=float)
    force = 0.01 * float(ea.min())
    res = solve_static(model, loads=_pull(len(prog.points), force))
    assert res.max_axial_strain == pytest.approx(force / float(ea.min()), rel=1e-4)


def test_an_absurd_stretch_is_not_physical_in_every_output(tmp_path):
    prog = _program()
    sim = simulate_filament(prog, steps=2, loads=_pull(len(prog.points), 3.0))
    assert sim.max_axial_strain[-1] > 2.0  # it converged, at several times its natural length
    run = describe_run(as_run(sim))
    assert run.scalars["max_axial_strain"][-1] > MAX_AXIAL_STRAIN
    verdict = run.metadata["physical"]
    assert verdict["verdict"] == "no" and "against their natural length" in verdict["reason"]
    assert "NOT PHYSICAL" in run_line(run)
    assert run.metadata["filaments"][0]["physical"]["verdict"] == "no"
    assert summarize(run)["physical"]["verdict"] == "no"
    path = write_results(
        tmp_path / "results.h5",
        design=run.design,
        edges=run.edges,
        branch=run.branch,
        positions=run.positions,
        scalars=run.scalars,
        fields=run.fields,
        units=run.units,
        metadata=run.metadata,
        static=run.static,
        programs=run.programs,
    )
    back = read_results(path)
    end = run_verdict(assess(back.scalars, back.metadata, back.n_steps))
    assert end.verdict == "no" and "strained" in end.text()


def test_an_ordinary_heating_ramp_stays_far_below_the_limit():
    sim = simulate_filament(_program(), steps=2)
    assert np.max(sim.max_axial_strain) < 1e-3
    assert describe_run(as_run(sim)).metadata["physical"]["verdict"] != "no"
