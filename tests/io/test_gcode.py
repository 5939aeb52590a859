"""G-code writer and strict reader: golden files per dialect, process settings, strictness,
rotary re-basing, serpentine order, profiles."""

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
from rotomorph.design.path import path_defect
from rotomorph.design.program import PrintProgram
from rotomorph.errors import GcodeParseError, InvalidParameterError, MachineLimitError
from rotomorph.io.gcode import Process, gcode_text, plan_programs, programs_sha256, write_gcode
from rotomorph.io.gcode_read import check_gcode, parse_gcode, read_gcode
from rotomorph.io.machine import MachineProfile, load_machine_profile
from rotomorph.io.print_order import reversed_program

GOLDEN = Path(__file__).parent / "golden"
MACHINES = sorted((Path(__file__).parents[2] / "examples" / "machines").glob("*.toml"))
GOLDEN_MACHINES = {
    "aerotech": MachineProfile(name="golden", dialect="aerotech"),
    "aerotech_nordson": MachineProfile(name="golden", dialect="aerotech", pressure_idiom="nordson"),
    "rs274": MachineProfile(name="golden", dialect="rs274"),
    "marlin": MachineProfile(name="golden", dialect="marlin"),
}
PROCESS = [Process(30, 20, 0.5, 0.25), Process(25, 25), Process(40, 0)]


def _small_programs() -> list[PrintProgram]:
    line = PrintPath.line((10, 10, 0.3), (12, 10, 0.3), 0.5)
    a = PrintProgram.from_rotation(line, 3.0, 10.0)  # ω* = 1
    b = PrintProgram.from_rotation(line.translated((0, 2, 0)), 1.5, 0.0, initial_angle=0.5)
    c = PrintProgram(
        a.points + np.array([0, 0, 0.6]), 2.0, -a.nozzle_angle, active_fraction=1.0, layer=1
    )
    return [a, b, c]


def _assert_same(read, progs, tol=1e-6):
    assert len(read) == len(progs)
    for r, p in zip(read, progs, strict=True):
        q = r.program
        np.testing.assert_allclose(q.points, p.points, atol=tol)
        turns = np.round((q.nozzle_angle[0] - p.nozzle_angle[0]) / (2 * np.pi))
        # the angle follows the design's dα/ds along the *written* (rounded) lengths, so it may
        # drift from the design's floats by the rounding of the lengths: each edge's turn times
        # the coordinates' rounding (~tol mm) over its length
        lengths = np.linalg.norm(np.diff(p.points, axis=0), axis=1)
        drift = tol * (1 + np.sum(np.abs(np.diff(p.nozzle_angle)) / np.minimum(lengths, 1.0)))
        np.testing.assert_allclose(q.nozzle_angle - 2 * np.pi * turns, p.nozzle_angle, atol=drift)
        np.testing.assert_allclose(q.speed[:-1], p.speed[:-1], rtol=1e-9)
        assert (q.radius, q.active_fraction, q.layer) == (p.radius, p.active_fraction, p.layer)
        assert (q.active_material, q.passive_material) == (p.active_material, p.passive_material)


@pytest.mark.parametrize("name", sorted(GOLDEN_MACHINES))
def test_golden_files(name):
    """Header, pressure idiom, dwell units and feeds of one small design per dialect."""
    text = gcode_text(_small_programs(), GOLDEN_MACHINES[name], process=PROCESS, layer_cure_s=60)
    golden = GOLDEN / f"small_{name}.gcode"
    if os.environ.get("ROTOMORPH_REGEN_GOLDEN"):
        golden.write_text(text)
    strip = lambda t: [ln for ln in t.splitlines() if not ln.startswith("; tool:")]  # noqa: E731
    assert strip(text) == strip(golden.read_text())
    assert f"; tool: rotomorph {rotomorph.__version__}" in text


def test_dialect_idioms():
    texts = {
        k: gcode_text(_small_programs(), m, process=PROCESS) for k, m in GOLDEN_MACHINES.items()
    }
    # prime dwell 0.5 s: seconds on aerotech and LinuxCNC, milliseconds on Marlin/Klipper/RRF
    assert "G4 P0.5" in texts["aerotech"] and "G4 P0.5" in texts["rs274"]
    assert "G4 P500" in texts["marlin"]
    # feeds: mecode's modal `G1 F<mm/s>` lines on aerotech; mm/min on every move elsewhere,
    # and on every marlin travel
    assert "G1 F3\n" in texts["aerotech"] and " F180\n" in texts["rs274"]
    assert all(" F" in ln for ln in texts["marlin"].splitlines() if ln.startswith(("G0", "G1")))
    assert "Call setPress P5 Q30\nCall setDispense P5 Q1\n" in texts["aerotech_nordson"]
    assert "togglePress" not in texts["aerotech_nordson"]  # explicit states, never a toggle
    assert "M68 E5 Q30.000\nM64 P5\n" in texts["rs274"] and "M65 P5" in texts["rs274"]
    assert "M42 P5 S76\n" in texts["marlin"]  # 30 psi of 100 at PWM 255
    for text in texts.values():
        assert "; rotary: C = nozzle angle" in text and "sign +1" in text
        assert all(" A" not in ln for ln in text.splitlines() if not ln.startswith(";"))


@pytest.mark.parametrize("name", sorted(GOLDEN_MACHINES))
def test_round_trip_process_and_structure(name):
    machine = GOLDEN_MACHINES[name]
    progs = _small_programs()
    text = gcode_text(progs, machine, process=PROCESS, layer_cure_s=60)
    report = check_gcode(text, machine)
    _assert_same(report.filaments, plan_programs(progs, machine))
    pwm = machine.max_pressure / 510 if "pwm" in (machine.pressure_template or "") else 1e-9
    got = [r.pressure for r in report.filaments]
    want = [{"active": 30, "passive": 20}, {"active": 25, "passive": 25}, {"active": 40}]
    for g, w in zip(got, want, strict=True):  # a pure-active filament drives one channel
        assert g.keys() == w.keys()
        assert all(abs(g[k] - w[k]) <= pwm for k in w)
    assert report.filaments[0].prime_dwell == 0.5 and report.filaments[0].release_dwell == 0.25
    assert report.filaments[1].prime_dwell == 0.0
    assert f"design-sha256: {programs_sha256(progs)}" in text
    header = float(re.search(r"; estimated print time: ([\d.]+) s", text)[1])
    assert header == pytest.approx(report.time, abs=0.1)
    assert report.max_start_turns <= 1.0


def test_pure_passive_drives_only_its_channel():
    line = PrintPath.line((10, 10, 0), (12, 10, 0), 0.5)
    prog = PrintProgram.from_rotation(line, 3.0, 0.0, active_fraction=0.0)
    text = gcode_text([prog], GOLDEN_MACHINES["aerotech"], process=Process(0.0, 25.0))
    # the active channel is only ever set off (at the start, explicitly), never driven
    assert [ln for ln in text.splitlines() if "P5" in ln] == ["Call setAlicatPress P5 Q0"]
    assert "Call setAlicatPress P6 Q25" in text
    with pytest.raises(InvalidParameterError, match="passive_pressure"):
        gcode_text([prog], GOLDEN_MACHINES["aerotech"], process=Process(25.0, 0.0))


def test_rotary_rebased_between_filaments():
    """ω* = 2 over 30 mm winds 32 turns; the next filament starts within one turn of 0."""
    line = PrintPath.line((10, 10, 0), (40, 10, 0), 0.05)
    progs = [
        PrintProgram.from_rotation(line.translated((0, 5 * k, 0)), 3.0, 20.0) for k in range(3)
    ]
    for rebase in ("g92", "unwind"):
        machine = MachineProfile(rotary_rebase=rebase, continuous_rotation=True, max_turns=40)
        text = gcode_text(progs, machine)
        report = check_gcode(text, machine)
        assert report.max_start_turns <= 1.0
        assert report.max_rotation <= machine.max_rotation * (1 + 1e-9)
        header = float(re.search(r"; estimated print time: ([\d.]+) s", text)[1])
        assert header == pytest.approx(report.time, abs=0.1)
        if rebase == "g92":
            assert text.count("G92 C") == 3  # two re-bases and the restore at the end
        else:  # unwinding 32 turns at 40 rad/s while lowering takes time, and is counted
            assert "G92" not in text and report.time > sum(p.duration for p in progs) + 2 * 5.0


def test_unwinding_too_far_names_rotary_rebase():
    line = PrintPath.line((10, 10, 0), (2610, 10, 0), 1.0)
    progs = [PrintProgram.from_rotation(line.translated((0, 5 * k, 0)), 3.0, 20.0) for k in (0, 1)]
    with pytest.raises(MachineLimitError, match="rotary_rebase"):
        gcode_text(progs, MachineProfile(rotary_rebase="unwind", envelope_max=(3000, 300, 100)))


def test_serpentine_reverses_the_same_physical_filament():
    path = PrintPath.from_segments([__import__("rotomorph").design.path.Sinusoid(1.0, 5.0, 2)])
    prog = PrintProgram.sinusoid_with_active_side(path.translated((10, 10, 0)), 3.0, "outer")
    rev = reversed_program(prog)
    np.testing.assert_allclose(rev.points, prog.points[::-1])
    # the interface normal toward the active half keeps its lab direction on every edge
    np.testing.assert_allclose(rev.interface_normals[::-1], prog.interface_normals, atol=0.05)
    np.testing.assert_allclose(
        np.median(np.abs(rev.interface_normals[::-1] - prog.interface_normals)), 0, atol=1e-3
    )
    back = PrintProgram(prog.points + np.array([0.0, 5.0, 0.0]), 3.0, 0.0)
    order = plan_programs([prog, back], MachineProfile())
    assert np.allclose(order[1].points[0], back.points[-1])  # printed from the near end
    assert np.allclose(
        plan_programs([prog, back], MachineProfile(), serpentine=False)[1].points, back.points
    )
    assert np.allclose(
        plan_programs([prog, back], MachineProfile(z_offset=0.6))[0].points[:, 2], 0.6
    )


def test_serpentine_mirrors_a_program_about_its_curves_tangent():
    from rotomorph.design.path import Arc, Line, chain_segments, tangent_headings

    segs = [Line(5.0), Arc(20.0, 1.0), Line(5.0)]
    pts, owner = chain_segments(segs, start=(10.0, 10.0, 0.0), spacing=1.0)
    psi = tangent_headings(segs, pts, owner)
    prog = PrintProgram.from_interface_angle(pts, 3.0, 0.5, tangent_heading=psi)
    rev = reversed_program(prog)
    np.testing.assert_allclose(rev.tangent_heading, (psi + np.pi)[::-1])
    # printed backward: the interface angle mirrors (alpha' = -alpha) about the same tangent,
    # at the arc's ends too, and the active half keeps its lab direction at every vertex
    np.testing.assert_allclose(rev.nozzle_angle, rev.tangent_heading + 0.5, atol=1e-12)
    np.testing.assert_allclose(
        rev.vertex_interface_normals[::-1], prog.vertex_interface_normals, atol=1e-12
    )
    twice = reversed_program(rev)  # the same program, up to whole turns
    np.testing.assert_allclose(twice.nozzle_angle, prog.nozzle_angle + 2 * np.pi, atol=1e-12)
    np.testing.assert_allclose(twice.tangent_heading, psi + 2 * np.pi, atol=1e-12)


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
    st.sampled_from(sorted(GOLDEN_MACHINES)),
    st.floats(0.0, 5.0),
)
def test_round_trip_random_programs(data, name, z):
    xy, speed, angle = data
    pts = np.column_stack([np.array(xy) + 100.0, np.full(len(xy), z)])
    if np.min(np.linalg.norm(np.diff(pts, axis=0), axis=1)) < 1e-2:
        return
    if path_defect(pts) is not None:  # a path that retraces itself is not a program
        return
    speed[-1] = speed[-2]
    prog = PrintProgram(pts, speed, angle)
    from dataclasses import replace

    machine = replace(GOLDEN_MACHINES[name], max_rotation=1e9)
    read = parse_gcode(gcode_text([prog], machine), machine)
    _assert_same(read, [prog], tol=2e-6)


def test_limits_refuse_and_leave_no_file(tmp_path):
    out = tmp_path / "print.gcode"
    with pytest.raises(MachineLimitError, match="max_rotation"):
        write_gcode(_small_programs(), out, MachineProfile(max_rotation=5.0))
    assert list(tmp_path.iterdir()) == []


def test_write_and_read_file(tmp_path):
    out = write_gcode(_small_programs(), tmp_path / "p.gcode", MachineProfile())
    assert [p.name for p in tmp_path.iterdir()] == ["p.gcode"]
    _assert_same(
        read_gcode(out, MachineProfile()), plan_programs(_small_programs(), MachineProfile())
    )
    with pytest.raises(InvalidParameterError, match="layer"):
        gcode_text(_small_programs()[::-1], MachineProfile())


@pytest.mark.parametrize(
    ("mutate", "match"),
    [
        (lambda t: t.replace("VELOCITY ON\n", "VELOCITY ON\nG28\n", 1), "unexpected command"),
        (lambda t: t.replace("Call setAlicatPress P5 Q30", "Call togglePress P5", 1), "unexpected"),
        (lambda t: t.replace(" C95.492966\n", " C95.492966 E1\n", 1), "unexpected word"),
        (
            lambda t: t.replace("Call setAlicatPress P5 Q30\nCall setAlicatPress P6 Q30\n", "", 1),
            "every pressure channel off",
        ),
        (lambda t: re.sub(r"; filament 0 [^\n]*\n", "", t, count=1), "without a '; filament"),
        (lambda t: t.replace("P6 Q30\n", "P6 Q30\nG0 Z5\n", 1), "travel move .G0. with a pressure"),
        (lambda t: t.replace("Call setAlicatPress P5 Q0\n", "", 2), "inside another filament"),
        (lambda t: t.replace("P6 Q30", "P7 Q30", 1), "unknown pressure port 7"),
        (lambda t: t.replace("G1 X12 Y12\n", "G0 X12 Y12 C5\n", 1), "rotary word on a rapid"),
        (lambda t: t.replace("G1 X10.5 Y10 C95.492966", "G1 C95.492966", 1), "rotary-only"),
        (lambda t: t.replace("G71\n", "", 1), "setup_lines"),
        (lambda t: t.replace("\nM2\n", "\n", 1), "must end with"),
        (
            lambda t: t.replace("Q30\nG1 F3\n", "Q30\nG1 F3\nG4 P1\nG1 X10.1 Y10 C1\nG4 P1\n", 1),
            "dwell in the middle",
        ),
    ],
)
def test_reader_is_strict(mutate, match):
    machine = MachineProfile()
    text = gcode_text(_small_programs()[:2], machine)
    parse_gcode(text, machine)
    assert mutate(text) != text
    with pytest.raises(GcodeParseError, match=match):
        parse_gcode(mutate(text), machine)


def _without_rebase(text: str) -> str:
    """The program with its first G92 removed and the later rotary words shifted to match."""
    head, tail = text.split("G92 C21.971863\n", 1)
    shift = lambda m: f" C{float(m[1]) + 360:.6f}"  # noqa: E731
    return (
        head + re.sub(r" C(-?[\d.]+)", shift, tail.split("G92")[0]) + "G92" + tail.split("G92")[1]
    )


@pytest.mark.parametrize(
    ("mutate", "key"),
    [
        (
            lambda t: t.replace("G1 X11 Y10 C190.985932", "G1 X11 Y10 C990.985932", 1),
            "max_rotation",
        ),
        (lambda t: t.replace("G1 F1.5\n", "G1 F300\n", 1), "max_feed"),
        (lambda t: t.replace("G1 F1.5\n", "G1 F0.001\n", 1), "min_feed"),
        (lambda t: t.replace("P6 Q30", "P6 Q300", 1), "max_pressure"),
        (lambda t: t.replace("G1 X10 Y10\n", "G1 X-10 Y10\n", 1), "envelope_min"),
        (lambda t: _without_rebase(t), "rotary_rebase"),
    ],
)
def test_checker_names_the_profile_key(mutate, key):
    machine = MachineProfile()
    text = gcode_text(_small_programs()[:2], machine)
    assert mutate(text) != text
    with pytest.raises(MachineLimitError, match=f"'{key}'"):
        check_gcode(mutate(text), machine)


def test_reader_rejects_other_dialect():
    text = gcode_text(_small_programs(), MachineProfile(dialect="aerotech"))
    with pytest.raises(GcodeParseError, match="line"):
        parse_gcode(text, MachineProfile(dialect="rs274"))


def test_machine_profile(tmp_path):
    f = tmp_path / "m.toml"
    f.write_text('[machine]\ndialect = "rs274"\nrotary_axis = "B"\nmax_rotation_deg_s = 360\n')
    m = load_machine_profile(f)
    assert m.rotary_axis == "B" and m.max_rotation == pytest.approx(2 * np.pi)
    assert m.feed_scale == 60.0 and m.dwell_template == "G4 P{s}" and m.source == "m.toml"
    assert MachineProfile().rotary_axis == "C"  # rotation about Z (RS-274/ISO)
    with pytest.raises(InvalidParameterError, match="rotary_axis"):
        MachineProfile(rotary_axis="F")
    with pytest.raises(InvalidParameterError, match="dialect"):
        MachineProfile(dialect="klipper")  # Klipper is a controller of the marlin dialect
    with pytest.raises(InvalidParameterError, match="'controller'"):
        MachineProfile(dialect="rs274", controller="klipper")
    with pytest.raises(InvalidParameterError, match=r"'rotary_rebase'.*Klipper"):
        MachineProfile(dialect="marlin", controller="klipper", rotary_rebase="g92")
    with pytest.raises(InvalidParameterError, match=r"'rotary_rebase'.*rotary union"):
        MachineProfile(continuous_rotation=False, rotary_rebase="g92")
    assert MachineProfile(dialect="marlin", controller="klipper").rotary_rebase == "unwind"
    assert MachineProfile(continuous_rotation=False).rotary_rebase == "unwind"
    with pytest.raises(InvalidParameterError, match="unknown setting"):
        MachineProfile.from_dict({"speed": 1})
    with pytest.raises(InvalidParameterError, match="pressure_template"):
        MachineProfile(dialect="rs274", pressure_template="M68 E{port}")
    with pytest.raises(InvalidParameterError, match="pressure_idiom"):
        MachineProfile(dialect="marlin", pressure_idiom="nordson")
    with pytest.raises(InvalidParameterError, match="dwell_template"):
        MachineProfile(dialect="marlin", dwell_template="G4")
    with pytest.raises(InvalidParameterError, match="header_file"):
        MachineProfile.from_dict({"header_file": "missing.txt"}, folder=tmp_path)


@pytest.mark.parametrize("path", MACHINES, ids=lambda p: p.stem)
def test_example_machine_profiles(path):
    machine = load_machine_profile(path)
    text = gcode_text(_small_programs(), machine, process=PROCESS, layer_cure_s=5)
    report = check_gcode(text, machine)
    _assert_same(report.filaments, plan_programs(_small_programs(), machine))
    assert f"; machine: {machine.name}, profile {path.name}" in text
    for line in machine.header_lines:
        assert line in text


def test_flow_model_pressures_scale_with_speed():
    """A speed series on one nozzle: with conductances the pressures follow v (Poiseuille),
    so every filament gets the same extruded section; an explicit pressure still wins."""
    from rotomorph.io.designfile import parse_design

    def filament(speed, y, **kw):
        seg = [{"kind": "line", "length": 5.0}]
        return {"speed": speed, "start": [10.0, y, 0.0], "spacing": 0.5, "segments": seg, **kw}

    data = {
        "schema_version": 1,
        "nozzle": {"active_conductance": 0.02, "passive_conductance": 0.01},
        "filaments": [
            filament(0.25, 10.0),
            filament(3.0, 15.0),
            filament(3.0, 20.0, active_fraction=1.0),
            filament(3.0, 25.0, active_pressure=50.0),
        ],
    }
    process = parse_design(data).gcode_options()["process"]
    area = np.pi * 0.3**2
    assert process[0].active_pressure == pytest.approx(0.25 * area * 0.5 / 0.02)
    assert process[0].passive_pressure == pytest.approx(0.25 * area * 0.5 / 0.01)
    assert process[1].active_pressure == pytest.approx(12 * process[0].active_pressure)
    assert process[2].active_pressure == pytest.approx(3.0 * area / 0.02)
    assert process[2].passive_pressure == 0.0  # unused channel: not driven
    assert process[3].active_pressure == 50.0
    with pytest.raises(InvalidParameterError, match="passive_conductance"):
        prog = PrintProgram.from_rotation(PrintPath.line((0, 0, 0), (1, 0, 0), 0.5), 3.0)
        Process.from_flow(prog, active_conductance=0.02, passive_conductance=None)
