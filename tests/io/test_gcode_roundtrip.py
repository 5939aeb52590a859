"""Every example design on every example machine, read back by rotomorph's own strict reader.

This is a round trip (the writer against its own reader), not a referee: the controllers' own
interpreters check the same programs in ``test_gcode_referee_linuxcnc.py`` and
``test_gcode_referee_klipper.py``, and ``test_gcode_static.py`` checks every dialect against its
documented command set. Here: dα/ds·v = ω on every move, pressures per filament as designed, no
move outside the envelope or above a limit, the angle within one turn at every filament start.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest

from rotomorph.io.designfile import load_design
from rotomorph.io.gcode import gcode_text, plan_programs
from rotomorph.io.gcode_read import check_gcode
from rotomorph.io.machine import load_machine_profile

ROOT = Path(__file__).parents[2] / "examples"
DESIGNS = sorted((ROOT / "designs").glob("*.toml"))
MACHINES = {p.stem: p for p in sorted((ROOT / "machines").glob("*.toml"))}
#: one profile per dialect for the full cross product; the other profiles get two designs
CROSS = ("aerotech_a3200_alicat", "linuxcnc", "marlin")


@functools.cache
def _written(design: Path, machine: str):
    m = load_machine_profile(MACHINES[machine])
    d = load_design(design)
    progs = d.to_programs()
    options = d.gcode_options()
    text = gcode_text(progs, m, layer_cure_s=30.0, **options)
    return m, progs, options["process"], text


def _check(design: Path, machine: str) -> None:
    m, progs, process, text = _written(design, machine)
    report = check_gcode(text, m, require_metadata=True)
    printed = plan_programs(progs, m)
    assert len(report.filaments) == len(printed)
    quantum = m.max_pressure / 510 if "{pwm}" in (m.pressure_template or "") else 1e-6
    for read, prog, proc in zip(report.filaments, printed, process, strict=True):
        want = dict(proc.channels(prog.active_fraction))
        assert read.pressure.keys() == want.keys()
        assert all(abs(read.pressure[k] - want[k]) <= quantum for k in want)
        np.testing.assert_allclose(read.program.points, prog.points, atol=1e-6)
        # dα/ds · v = ω on every print move, to 1e-6 of max(|ω|, 1 rad/s)
        got = np.diff(read.program.nozzle_angle) / read.program.path.edge_lengths
        expected = np.diff(prog.nozzle_angle) / prog.path.edge_lengths * prog.speed[:-1]
        got = got * read.program.speed[:-1]
        assert np.all(np.abs(got - expected) <= 1e-6 * np.maximum(np.abs(expected), 1.0))
    assert report.max_rotation <= m.max_rotation * (1 + 1e-9)
    assert report.max_start_turns <= 1.0 + 1e-9


@pytest.mark.parametrize("machine", CROSS)
@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_every_example_design_on_every_dialect(design, machine):
    _check(design, machine)


@pytest.mark.parametrize("machine", sorted(set(MACHINES) - set(CROSS)))
@pytest.mark.parametrize("design", ["composite_rotation", "sinusoids"])
def test_other_example_machines(design, machine):
    _check(ROOT / "designs" / f"{design}.toml", machine)
