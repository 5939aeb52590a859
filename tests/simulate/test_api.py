"""The top-level API: lazy exports, the common path, save/plot, compact reprs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import rotomorph

DESIGN = """schema_version = 1
name = "api"
[[filaments]]
name = "w*=0.25"
rotation_number = 0.25
spacing = 1.0
segments = [{ kind = "line", length = 12.0 }]
"""


@pytest.fixture(scope="module")
def design_path(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("api") / "design.toml"
    path.write_text(DESIGN)
    return path


def test_import_is_cheap_and_every_export_resolves():
    code = "import sys, rotomorph; print('numpy' in sys.modules, 'numba' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "False"]
    for name in rotomorph.__all__:
        assert getattr(rotomorph, name) is not None, name
    assert set(rotomorph.__all__) <= set(dir(rotomorph))
    with pytest.raises(AttributeError, match="no attribute 'simulat'"):
        rotomorph.simulat


def test_common_path(design_path, tmp_path):
    design = rotomorph.load_design(design_path)
    (shape,) = rotomorph.predict(design)
    assert shape.label in ("helix", "coil", "straight", "ring") and 0 < shape.end_to_end_ratio < 1
    run = rotomorph.simulate(design_path, steps=1)
    assert isinstance(run, rotomorph.DesignSimulation)
    paths = run.save(tmp_path / "run", movie=False)
    assert tmp_path / "run" / "results.h5" in paths
    back = rotomorph.read_results(tmp_path / "run" / "results.h5")
    np.testing.assert_allclose(back.positions, run.positions)
    gcode = rotomorph.write_gcode(design, tmp_path / "a.gcode")
    assert gcode.read_text().count("G1") > 10
    with pytest.raises(rotomorph.InvalidParameterError, match="design: must be a Design"):
        rotomorph.simulate(42)


def test_a_single_filament_simulation_saves_and_plots(design_path, tmp_path):
    (program,) = rotomorph.load_design(design_path).to_programs()
    sim = rotomorph.simulate(program, steps=1)
    assert isinstance(sim, rotomorph.FilamentSimulation)
    files = rotomorph.write_run(sim, tmp_path / "one", movie=False)
    assert (tmp_path / "one" / "summary.json") in files
    back = rotomorph.read_results(tmp_path / "one" / "results.h5")
    np.testing.assert_allclose(back.positions[-1], sim.positions[-1])
    assert sim.save(tmp_path / "two", movie=False) and (tmp_path / "two" / "results.h5").exists()
    pngs = [p for p in sim.plot(tmp_path / "figs") if p.suffix == ".png"]
    assert pngs and all(p.stat().st_size > 5_000 for p in pngs)


def test_reprs_are_compact(design_path):
    (program,) = rotomorph.load_design(design_path).to_programs()
    sim = rotomorph.simulate(program, steps=1)
    for obj in (program, sim, sim.to_run()):
        text = repr(obj)
        assert len(text) < 700 and "\n" not in text and "[[" not in text, text
        assert "array(" in text
        assert rotomorph.__name__ and obj._repr_html_().startswith("<table>")
    assert "points=array(13, 3)" in repr(program)
    np.testing.assert_allclose(program.rotation_number, 0.25, rtol=1e-9)  # a property
