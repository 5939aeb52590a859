"""G-code writer and strict reader: round trip, golden files, limits, strictness."""

from __future__ import annotations

import os
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import rotomorph
from rotomorph.design.path import Path as PrintPath
from rotomorph.design.program import PrintProgram
from rotomorph.errors import GcodeParseError, InvalidParameterError, MachineLimitError
from rotomorph.io.gcode import gcode_text, programs_sha256, write_gcode
from rotomorph.io.gcode_read import parse_gcode, read_gcode
from rotomorph.io.machine import MachineProfile, load_machine_profile

GOLDEN = Path(__file__).parent / "golden"
DIALECTS = ("aerotech", "rs274", "marlin")


def _small_programs() -> list[PrintProgram]:
    line = PrintPath.line((10, 10, 0.3), (12, 10, 0.3), 0.5)
    a = PrintProgram.from_rotation(line, 3.0, 10.0)  # ω* = 1
    b = PrintProgram.from_rotation(line.translated((0, 2, 0)), 1.5, 0.0, initial_angle=0.5)
    c = PrintProgram(
        a.points + np.array([0, 0, 0.6]), 2.0, -a.nozzle_angle, active_fraction=1.0, layer=1
    )
    return [a, b, c]


def _assert_same(read, progs, tol=1e-4):
    assert len(read) == len(progs)
    for r, p in zip(read, progs, strict=True):
        q = r.program
        np.testing.assert_allclose(q.points, p.points, atol=tol)
        np.testing.assert_allclose(q.nozzle_angle, p.nozzle_angle, atol=tol)
        np.testing.assert_allclose(q.speed[:-1], p.speed[:-1], atol=tol)
        assert (q.radius, q.active_fraction, q.layer) == (p.radius, p.active_fraction, p.layer)
        assert (q.active_material, q.passive_material) == (p.active_material, p.passive_material)


@pytest.mark.parametrize("dialect", DIALECTS)
def test_golden_files(dialect):
    machine = MachineProfile(
        name="golden", dialect=dialect, rotary_axis="C" if dialect != "aerotech" else "A"
    )
    text = gcode_text(
        _small_programs(), machine, pressures=[(30, 20), (25, 25), (40, 0)], layer_cure_s=600
    )
    golden = GOLDEN / f"small_{dialect}.gcode"
    if os.environ.get("ROTOMORPH_REGEN_GOLDEN"):
        golden.write_text(text)
    strip = lambda t: [ln for ln in t.splitlines() if not ln.startswith("; tool:")]  # noqa: E731
    assert strip(text) == strip(golden.read_text())
    assert f"; tool: rotomorph {rotomorph.__version__}" in text


@pytest.mark.parametrize("dialect", DIALECTS)
def test_round_trip_and_emitted_structure(dialect):
    progs = _small_programs()
    machine = MachineProfile(dialect=dialect)
    text = gcode_text(progs, machine, pressures=[(30, 20), (25, 25), (40, 0)], layer_cure_s=60)
    read = parse_gcode(text, machine)
    _assert_same(read, progs)
    assert [r.pressure for r in read] == [(30, 20), (25, 25), (40, 0)]
    assert f"design-sha256: {programs_sha256(progs)}" in text
    assert re.search(r"; estimated print time: [\d.]+ s", text)
    g1 = [ln for ln in text.splitlines() if ln.startswith("G1")]
    assert all(" X" in ln and " Y" in ln and " A" in ln and " F" in ln for ln in g1)
    feed = float(g1[0].split("F")[1])
    assert feed == pytest.approx(3.0 * (1 if dialect == "aerotech" else 60))
    assert "toggle" not in text.lower()
    # dα_n/ds = ω/v on every move of the first (ω = 10 rad/s, v = 3 mm/s) filament
    q = read[0].program
    slope = np.diff(q.nozzle_angle) / np.diff(q.arc_length)
    np.testing.assert_allclose(slope, 10.0 / 3.0, rtol=1e-3)


finite = st.floats(-50, 50, allow_nan=False)


@settings(max_examples=25, deadline=None)
@given(
    st.integers(2, 12).flatmap(
        lambda n: st.tuples(
            st.lists(st.tuples(finite, finite), min_size=n, max_size=n, unique=True),
            st.lists(st.floats(0.1, 20), min_size=n, max_size=n),
            st.lists(st.floats(-20, 20), min_size=n, max_size=n),
        )
    ),
    st.sampled_from(DIALECTS),
    st.floats(0.0, 5.0),
)
def test_round_trip_random_programs(data, dialect, z):
    xy, speed, angle = data
    pts = np.column_stack([np.array(xy) + 100.0, np.full(len(xy), z)])
    if np.min(np.linalg.norm(np.diff(pts, axis=0), axis=1)) < 1e-2:
        return
    speed[-1] = speed[-2]
    prog = PrintProgram(pts, speed, angle)
    machine = MachineProfile(dialect=dialect, max_rotation=1e9)
    _assert_same(parse_gcode(gcode_text([prog], machine), machine), [prog])


@pytest.mark.parametrize(
    ("machine", "programs", "match"),
    [
        (MachineProfile(envelope_max=(11.0, 300.0, 100.0)), None, "leaves the envelope"),
        (MachineProfile(envelope_max=(300.0, 300.0, 1.0)), None, "travel height"),
        (MachineProfile(max_feed=2.5), None, "max_feed"),
        (MachineProfile(max_rotation=5.0), None, "max_rotation"),
        (MachineProfile(max_pressure=35.0), None, "pressure 40"),
    ],
)
def test_limits_refuse_and_leave_no_file(tmp_path, machine, programs, match):
    out = tmp_path / "print.gcode"
    with pytest.raises(MachineLimitError, match=match):
        write_gcode(_small_programs(), out, machine, pressures=[(30, 20), (25, 25), (40, 0)])
    assert list(tmp_path.iterdir()) == []


def test_write_and_read_file(tmp_path):
    out = write_gcode(_small_programs(), tmp_path / "p.gcode", MachineProfile())
    assert [p.name for p in tmp_path.iterdir()] == ["p.gcode"]
    _assert_same(read_gcode(out, MachineProfile()), _small_programs())
    with pytest.raises(InvalidParameterError, match="layer"):
        gcode_text(_small_programs()[::-1], MachineProfile())


@pytest.mark.parametrize(
    ("mutate", "match"),
    [
        (lambda t: t.replace("G90\n", "G90\nG28\n", 1), r"line 15: unexpected command"),
        (
            lambda t: t.replace("Call setAlicatPress P5 Q30", "Call togglePress P5", 1),
            "unexpected command",
        ),
        (lambda t: t.replace(" F3\n", " F3 E1\n", 1), "malformed word|unexpected word"),
        (
            lambda t: t.replace("Call setAlicatPress P5 Q30\nCall setAlicatPress P6 Q30\n", "", 1),
            "both pressures off",
        ),
        (lambda t: re.sub(r"; filament 0 [^\n]*\n", "", t, count=1), "without a '; filament"),
        (
            lambda t: t.replace("P6 Q30\n", "P6 Q30\nG0 Z5\n", 1),
            "travel move .G0. with a pressure on",
        ),
        (lambda t: t.replace("Call setAlicatPress P5 Q0\n", "", 1), "inside another filament"),
        (lambda t: t.replace("P6 Q30", "P7 Q30", 1), "unknown pressure port 7"),
    ],
)
def test_reader_is_strict(mutate, match):
    machine = MachineProfile()
    text = gcode_text(_small_programs()[:2], machine)
    parse_gcode(text, machine)
    with pytest.raises(GcodeParseError, match=match):
        parse_gcode(mutate(text), machine)


def test_reader_rejects_other_dialect():
    text = gcode_text(_small_programs(), MachineProfile(dialect="aerotech"))
    with pytest.raises(GcodeParseError, match="line"):
        parse_gcode(text, MachineProfile(dialect="rs274"))


def test_machine_profile(tmp_path):
    f = tmp_path / "m.toml"
    f.write_text('[machine]\ndialect = "rs274"\nrotary_axis = "C"\nmax_rotation_deg_s = 360\n')
    m = load_machine_profile(f)
    assert m.rotary_axis == "C" and m.max_rotation == pytest.approx(2 * np.pi)
    assert m.feed_scale == 60.0
    with pytest.raises(InvalidParameterError, match="rotary_axis"):
        MachineProfile(rotary_axis="F")
    with pytest.raises(InvalidParameterError, match="dialect"):
        MachineProfile(dialect="klipper")
    with pytest.raises(InvalidParameterError, match="unknown setting"):
        MachineProfile.from_dict({"speed": 1})
    with pytest.raises(InvalidParameterError, match="pressure_template"):
        MachineProfile(pressure_template="M800 P{port}")
