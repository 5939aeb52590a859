"""Nothing from a design or a profile reaches a G-code program unescaped; travel clears the
part; feeds, rotation, pressure and z are range-checked; limits name the profile key."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from rotomorph.cli import EXIT_OK, EXIT_USAGE, main
from rotomorph.design.path import Path as PrintPath
from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError, MachineLimitError
from rotomorph.io.gcode import Process, gcode_text
from rotomorph.io.gcode_read import parse_gcode
from rotomorph.io.machine import MachineProfile, load_machine_profile

INJECT = ["lce\nG0 Z-50", "lce\rG0 Z-50", "lce\x00", "x\x1b[2J", "a\u2028G0 Z-50", "lce\t"]

DESIGN = """schema_version = 1
name = {name}
description = {description}

[[filaments]]
name = {fname}
speed = 3.0
active_material = {active}
passive_material = {passive}
start = [10.0, 10.0, 0.0]
spacing = 0.5
segments = [{{ kind = "line", length = 5.0 }}]
"""
FIELDS = ("name", "description", "fname", "active", "passive")


def _toml_str(text: str) -> str:
    return '"' + "".join(c if c.isalnum() or c in " .-" else f"\\u{ord(c):04x}" for c in text) + '"'


def _design(tmp_path: Path, **strings: str) -> Path:
    values = {"name": "ok", "description": "fine", "fname": "f", "active": "lce"}
    values["passive"] = "acrylate"
    values.update(strings)
    path = tmp_path / "d.toml"
    path.write_text(DESIGN.format(**{k: _toml_str(v) for k, v in values.items()}))
    return path


def _no_injected_block(text: str) -> None:
    for line in text.splitlines():
        assert all(32 <= ord(c) < 127 for c in line), repr(line)
        assert not re.match(r"\s*G0 Z-50", line), line


@pytest.mark.parametrize("field", FIELDS)
@pytest.mark.parametrize("bad", INJECT[:3])
def test_injection_through_every_design_string(tmp_path, capsys, field, bad):
    out = tmp_path / "p.gcode"
    code = main(["gcode", str(_design(tmp_path, **{field: bad})), "-o", str(out)])
    if code == EXIT_OK:  # free text that never reaches the program is allowed
        assert field in ("name", "description", "fname")
        _no_injected_block(out.read_text())
    else:
        assert code == EXIT_USAGE
        assert not out.exists()
    capsys.readouterr()


@pytest.mark.parametrize("bad", INJECT)
def test_material_names_refused_in_the_api(bad):
    line = PrintPath.line((10, 10, 0), (12, 10, 0), 0.5)
    prog = PrintProgram.from_rotation(line, 3.0, 0.0, active_material=bad)
    with pytest.raises(InvalidParameterError, match="active material"):
        gcode_text([prog], MachineProfile())


def test_unknown_material_refused_like_validate(tmp_path, capsys):
    design = _design(tmp_path, active="unobtainium")
    for cmd in (["validate", str(design)], ["gcode", str(design), "-o", str(tmp_path / "x")]):
        assert main(cmd) == EXIT_USAGE
        assert "unobtainium" in capsys.readouterr().err


PROFILE_STRINGS = (
    "name",
    "dialect",
    "pressure_idiom",
    "pressure_template",
    "valve_on_template",
    "valve_off_template",
    "dwell_template",
    "uv_on_template",
    "uv_off_template",
    "rotary_units",
    "rotary_rebase",
    "x_axis",
    "y_axis",
    "z_axis",
    "rotary_axis",
)
PROFILE_LINES = ("setup_lines", "end_lines", "header_lines", "footer_lines")
_SUFFIX = {
    "pressure_template": " {port} {psi}",
    "valve_on_template": " {port}",
    "valve_off_template": " {port}",
    "dwell_template": " {s}",
}


@pytest.mark.parametrize("key", PROFILE_STRINGS + PROFILE_LINES)
@pytest.mark.parametrize("bad", INJECT)
def test_injection_through_every_profile_string(tmp_path, key, bad):
    value: object = bad + _SUFFIX.get(key, "")
    if key in PROFILE_LINES:
        value = ["G90", value]
    base = {"dialect": "rs274"} | {key: value}
    with pytest.raises(InvalidParameterError, match=f"'{key}'"):
        MachineProfile(**base)  # type: ignore[arg-type]
    f = tmp_path / "m.toml"
    toml = (
        "[" + ", ".join(_toml_str(v) for v in value) + "]"
        if isinstance(value, list)
        else _toml_str(str(value))
    )
    dialect = "" if key == "dialect" else 'dialect = "rs274"\n'
    f.write_text(f"[machine]\n{dialect}{key} = {toml}\n")
    with pytest.raises(InvalidParameterError, match=f"'{key}'"):
        load_machine_profile(f)


def test_injection_through_a_header_file(tmp_path):
    (tmp_path / "h.txt").write_bytes(b"DVAR $a\r\nG0 Z-50\x1b\n")
    f = tmp_path / "m.toml"
    f.write_text('[machine]\nheader_file = "h.txt"\n')
    with pytest.raises(InvalidParameterError, match="header_lines"):
        load_machine_profile(f)


@pytest.mark.parametrize("role", ["active_material", "passive_material"])
def test_injection_through_lattice_materials(tmp_path, capsys, role):
    design = tmp_path / "lattice.toml"
    design.write_text(
        "schema_version = 1\n[lattice]\nn = 2\nghost_nodes = 2\nlayers = 1\n"
        f"origin = [20.0, 20.0, 0.0]\n{role} = {_toml_str('lce' + chr(10) + 'G0 Z-50')}\n"
    )
    out = tmp_path / "p.gcode"
    assert main(["gcode", str(design), "-o", str(out)]) == EXIT_USAGE
    assert not out.exists()
    capsys.readouterr()


def test_axis_letters_and_ports_cannot_inject():
    with pytest.raises(InvalidParameterError, match="rotary_axis"):
        MachineProfile(rotary_axis="\n")
    with pytest.raises(InvalidParameterError, match="active_port"):
        MachineProfile.from_dict({"active_port": "5\nG0 Z-50"})


def test_profile_file_with_control_characters_in_its_name(tmp_path):
    f = tmp_path / "m\nG0 Z-50.toml"
    f.write_text("[machine]\n")
    with pytest.raises(InvalidParameterError, match="path"):
        load_machine_profile(f)


def _climb_then_next() -> list[PrintProgram]:
    """A filament climbing to z = 10 mm, then one starting at z = 0 beside its start."""
    t = np.linspace(0, 1, 11)
    climb = np.column_stack([10 + 10 * t, np.full_like(t, 10.0), 10 * t])
    first = PrintProgram(climb, 3.0, 0.0)
    second = PrintProgram.from_rotation(PrintPath.line((30, 10, 0), (15, 10, 0), 0.5), 3.0)
    return [first, second]


@pytest.mark.parametrize("dialect", ["aerotech", "rs274", "marlin"])
def test_travel_never_crosses_the_printed_part(dialect):
    machine = MachineProfile(dialect=dialect)
    progs = _climb_then_next()
    text = gcode_text(progs, machine)
    top = max(float(p.points[:, 2].max()) for p in progs)
    z = None
    printed_top = -np.inf
    travelled = 0
    for line in text.splitlines():
        if not line.startswith(("G0", "G1")):
            continue
        words = {w[0]: float(w[1:]) for w in line.split()[1:] if w[0] in "XYZ"}
        # a travel carries no rotary word: G0 (rs274, marlin) or G1 at travel_feed (aerotech)
        travel = line.startswith("G0") or f" {machine.rotary_axis}" not in line
        if not travel:
            z = words.get("Z", z)
            if "X" in words:  # a print move (the lowering G1 moves only Z and the rotary axis)
                printed_top = max(printed_top, z)
        else:
            if "Z" in words:
                z = words["Z"]
            if "X" in words and printed_top > -np.inf:  # a horizontal travel after printing
                assert z >= printed_top + machine.lift - 1e-9
                travelled += 1
    assert travelled == 1 and printed_top == pytest.approx(top)
    assert len(parse_gcode(text, machine)) == 2


def test_travel_above_the_envelope_names_lift():
    with pytest.raises(MachineLimitError, match="'lift'"):
        gcode_text(_climb_then_next(), MachineProfile(envelope_max=(300.0, 300.0, 11.0)))


@pytest.mark.parametrize("speed", [4e-5, 0.009])
def test_feed_below_the_minimum_is_refused(speed):
    line = PrintPath.line((10, 10, 0), (12, 10, 0), 0.5)
    prog = PrintProgram.from_rotation(line, speed, 0.0)
    with pytest.raises(MachineLimitError, match="min_feed"):
        gcode_text([prog], MachineProfile())
    ok = gcode_text([prog], MachineProfile(min_feed=1e-5))
    feeds = re.findall(r"^G1 (?:.* )?F(\S+)$", ok, flags=re.M)  # aerotech: G1 F lines
    assert all(re.fullmatch(r"\d+\.?\d*", f) for f in feeds)  # no exponent notation
    feeds = [float(f) for f in feeds]
    assert feeds and min(feeds) == pytest.approx(speed, rel=1e-9)


def test_zero_feed_cannot_be_expressed():
    with pytest.raises(InvalidParameterError, match="speed"):
        PrintProgram(np.array([[0, 0, 0], [1, 0, 0.0]]), 0.0, 0.0)
    with pytest.raises(InvalidParameterError, match="min_feed"):
        MachineProfile(min_feed=0.0)


@pytest.mark.parametrize(
    ("machine", "pressures", "key"),
    [
        (MachineProfile(max_feed=2.0), (30, 30), "max_feed"),
        (MachineProfile(max_rotation=1.0), (30, 30), "max_rotation"),
        (MachineProfile(max_pressure=20.0), (30, 10), "max_pressure"),
        (MachineProfile(min_pressure=5.0), (30, 0), "min_pressure"),
        (MachineProfile(envelope_min=(0.0, 0.0, 0.5)), (30, 30), "envelope_min"),
        (MachineProfile(envelope_max=(11.0, 300.0, 100.0)), (30, 30), "envelope_max"),
    ],
)
def test_every_limit_names_its_profile_key(machine, pressures, key):
    line = PrintPath.line((10, 10, 0.3), (12, 10, 0.3), 0.5)
    prog = PrintProgram.from_rotation(line, 3.0, 10.0)
    with pytest.raises(MachineLimitError, match=f"machine profile key '{key}'"):
        gcode_text([prog], machine, process=Process(*pressures))


def test_profile_values_are_range_checked():
    for kwargs, key in [
        ({"max_feed": float("nan")}, "max_feed"),
        ({"lift": -1.0}, "lift"),
        ({"max_rotation": float("inf")}, "max_rotation"),
        ({"min_pressure": -1.0}, "min_pressure"),
        ({"envelope_max": (1.0, 1.0, float("nan"))}, "envelope_max"),
        ({"min_feed": 60.0}, "min_feed"),
    ]:
        with pytest.raises(InvalidParameterError, match=f"'{key}'"):
            MachineProfile(**kwargs)
    with pytest.raises(InvalidParameterError, match="'max_feed'"):
        MachineProfile.from_dict({"max_feed": "fast"})


def test_default_machine_is_stated(tmp_path, capsys):
    design = _design(tmp_path)
    out = tmp_path / "p.gcode"
    assert main(["gcode", str(design), "-o", str(out)]) == EXIT_OK
    assert "built-in default machine" in capsys.readouterr().err
    assert "; machine: generic, built-in default" in out.read_text()
    prof = tmp_path / "lab.toml"
    prof.write_text('[machine]\nname = "lab"\n')
    assert main(["gcode", str(design), "-o", str(out), "--machine", str(prof)]) == EXIT_OK
    assert "built-in" not in capsys.readouterr().err
    assert "; machine: lab, profile lab.toml" in out.read_text()


MACHINES = Path(__file__).parents[2] / "examples" / "machines"
EXAMPLES = Path(__file__).parents[2] / "examples" / "designs"


def test_cli_preview_and_check(tmp_path, capsys):
    from PIL import Image

    out = tmp_path / "sinusoids.gcode"
    machine = str(MACHINES / "linuxcnc.toml")
    design = str(EXAMPLES / "sinusoids.toml")
    assert main(["gcode", design, "-o", str(out), "--machine", machine, "--preview"]) == EXIT_OK
    img = np.asarray(Image.open(out.with_suffix(".png")).convert("RGB"), dtype=float)
    assert img.std() > 5.0 and np.sum(np.ptp(img, axis=2) > 40) > 500
    capsys.readouterr()
    assert main(["gcode", "--check", str(out), "--machine", machine]) == EXIT_OK
    assert "ok: 2 filament(s)" in capsys.readouterr().out
    bad = tmp_path / "bad.gcode"
    text = out.read_text()
    cut = text.index("; end filament 0")
    bad.write_text(text[:cut].rsplit("M65 P0\n", 1)[0] + text[cut:])  # a valve left open
    assert main(["gcode", "--check", str(bad), "--machine", machine]) == EXIT_USAGE
    assert "line " in capsys.readouterr().err
    other = str(MACHINES / "marlin.toml")
    assert main(["gcode", "--check", str(out), "--machine", other]) == EXIT_USAGE
    assert main(["gcode", "--check", str(out)]) == EXIT_USAGE
    assert "--machine" in capsys.readouterr().err
    code = main(["gcode", design, "-o", str(out), "--machine", machine, "--dialect", "marlin"])
    assert code == EXIT_USAGE and "'dialect'" in capsys.readouterr().err


def test_design_file_process_per_filament(tmp_path):
    design = tmp_path / "d.toml"
    design.write_text(
        "schema_version = 1\n[nozzle]\nactive_pressure = 20.0\nprime_dwell = 0.3\n"
        "[[filaments]]\nspeed = 0.25\nactive_pressure = 12.0\npassive_pressure = 8.0\n"
        "start = [10.0, 10.0, 0.0]\nspacing = 0.5\nsegments = [{ kind = 'line', length = 2.0 }]\n"
        "[[filaments]]\nspeed = 3.0\nactive_fraction = 1.0\nrelease_dwell = 0.2\n"
        "start = [10.0, 15.0, 0.0]\nspacing = 0.5\nsegments = [{ kind = 'line', length = 2.0 }]\n"
    )
    out = tmp_path / "p.gcode"
    assert main(["gcode", str(design), "-o", str(out)]) == EXIT_OK
    read = parse_gcode(out.read_text(), MachineProfile())
    assert [r.pressure for r in read] == [{"active": 12.0, "passive": 8.0}, {"active": 20.0}]
    assert [(r.prime_dwell, r.release_dwell) for r in read] == [(0.3, 0.0), (0.3, 0.2)]


@pytest.mark.parametrize("cure", [-1.0, float("nan"), float("inf"), 1e9])
def test_the_library_refuses_a_cure_dwell_outside_the_documented_range(cure):
    """``write_gcode``/``gcode_text`` refuse what ``--cure`` refuses (a 31-year dwell), not
    only the CLI: a script calling the library gets the same one-line error."""
    from rotomorph.design.path import Line
    from rotomorph.io.design_limits import MAX_LAYER_CURE_S

    path = PrintPath.from_segments([Line(10.0)], spacing=0.5)
    program = PrintProgram.from_rotation(path, speed=3.0, rotation=0.0)
    with pytest.raises(InvalidParameterError, match=f"layer_cure_s.*{MAX_LAYER_CURE_S:g}"):
        gcode_text([program], MachineProfile(), layer_cure_s=cure)
