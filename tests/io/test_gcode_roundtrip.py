"""Every example design on every example machine: written, read back by the strict reader and
by an independent parser (gcodeparser), with dα/ds·v = ω on every move, pressures per filament
as designed, no move outside the envelope or above a limit, the angle within one turn between
filaments."""

from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np
import pytest
from gcodeparser import parse_gcode_lines

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


def _independent_moves(text: str, m):
    """(start, end, feed mm/s, kind) of every motion block, by gcodeparser's reading."""
    pos = {a: math.nan for a in "XYZ"} | {m.rotary_axis: 0.0}
    feed = None
    out = []
    for line in parse_gcode_lines(text):
        letter, number = line.command
        if letter != "G" or number not in (0, 1, 92):
            continue
        params = dict(line.params)
        if number == 92:
            pos = pos | {m.rotary_axis: float(params.pop(m.rotary_axis))}
            assert not params
            continue
        if "F" in params:
            feed = float(params.pop("F")) / m.feed_scale
        if not params:
            continue
        new = pos | {k: float(v) for k, v in params.items()}
        assert set(params) <= set(pos)
        out.append((dict(pos), new, feed, number))
        pos = new
    return out


def _check(design: Path, machine: str) -> None:
    m, progs, process, text = _written(design, machine)
    report = check_gcode(text, m, require_metadata=True)
    printed = plan_programs(progs, m)
    assert len(report.filaments) == len(printed)
    # pressures per filament as designed (pure filaments drive one channel)
    quantum = m.max_pressure / 510 if "{pwm}" in (m.pressure_template or "") else 1e-6
    for read, prog, proc in zip(report.filaments, printed, process, strict=True):
        want = dict(proc.channels(prog.active_fraction))
        assert read.pressure.keys() == want.keys()
        assert all(abs(read.pressure[k] - want[k]) <= quantum for k in want)
        np.testing.assert_allclose(read.program.points, prog.points, atol=1e-6)
    # independent parser: every move in the envelope; every rotary move within the limit
    moves = _independent_moves(text, m)
    lo, hi = np.array(m.envelope_min), np.array(m.envelope_max)
    expected = np.concatenate(
        [np.diff(p.nozzle_angle) / p.path.edge_lengths * p.speed[:-1] for p in printed]
    )
    omega = []
    for a, b, feed, g in moves:
        xyz = np.array([b["X"], b["Y"], b["Z"]])
        known = ~np.isnan(xyz)
        assert (xyz[known] >= lo[known] - 1e-9).all() and (xyz[known] <= hi[known] + 1e-9).all()
        turn = (b[m.rotary_axis] - a[m.rotary_axis]) / m.rotary_scale
        if g == 0:
            assert turn == 0  # no rotary word at rapid
            if m.dialect == "marlin":
                assert feed is not None  # feeds on every travel
            continue
        length = math.dist([a["X"], a["Y"], a["Z"]], [b["X"], b["Y"], b["Z"]])
        assert length > 0 and feed is not None
        assert abs(turn) * feed / length <= m.max_rotation * (1 + 1e-9)
        if (a["X"], a["Y"]) != (b["X"], b["Y"]):  # a print move
            assert m.min_feed <= feed <= m.max_feed
            omega.append(turn * feed / length)
    # dα/ds · v = ω on every print move, to 1e-6 of max(|ω|, 1 rad/s)
    omega = np.array(omega)
    assert omega.shape == expected.shape
    assert np.all(np.abs(omega - expected) <= 1e-6 * np.maximum(np.abs(expected), 1.0))
    # the angle word never exceeds one turn between filaments
    assert report.max_start_turns <= 1.0 + 1e-9


@pytest.mark.parametrize("machine", CROSS)
@pytest.mark.parametrize("design", DESIGNS, ids=lambda p: p.stem)
def test_every_example_design_on_every_dialect(design, machine):
    _check(design, machine)


@pytest.mark.parametrize("machine", sorted(set(MACHINES) - set(CROSS)))
@pytest.mark.parametrize("design", ["composite_rotation", "sinusoids"])
def test_other_example_machines(design, machine):
    _check(ROOT / "designs" / f"{design}.toml", machine)
