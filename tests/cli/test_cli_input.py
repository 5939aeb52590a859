"""Bad input on the command line: one-line errors, exit 2, nothing written, same as the API."""

from __future__ import annotations

from pathlib import Path

import pytest

from rotomorph.cli import EXIT_OK, EXIT_USAGE, main

LATTICE = "schema_version = 1\n[lattice]\nn = {n}\n"
FILAMENT = (
    "schema_version = 1\n[[filaments]]\nspacing = 1.0\n"
    'segments = [{ kind = "line", length = 10.0 }]\n'
)


def _error(capsys) -> str:
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and err.startswith("rotomorph: error: "), err
    return err.removeprefix("rotomorph: error: ")


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "design.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("text", "flags", "message"),
    [
        (
            LATTICE.format(n=3),
            ["--actuation", "swapped", "--temperature", "150"],
            "--temperature: does not apply to the 'swapped' actuation",
        ),
        (
            LATTICE.format(n=3),
            ["--actuation", "radius", "--start-temperature", "20"],
            "--start-temperature: does not apply to the 'radius' actuation",
        ),
        (LATTICE.format(n=3), ["--temperature", "1e12"], r"--temperature: must lie in [-50"),
        (LATTICE.format(n=3), ["--spacing", "0.5"], "--spacing: applies to filaments"),
        (FILAMENT, ["--actuation", "thermal"], "--actuation: applies to lattices only"),
        (FILAMENT, ["--temperature", "1e12"], r"--temperature: must lie in [-50, 300] °C"),
        (FILAMENT, ["--temperature", "nan"], "--temperature: must be finite"),
        (FILAMENT, ["--steps", "0"], "--steps: must be a whole number in [1, 10000]"),
        # before: "filaments[0].spacing: must be >= 0.001 mm" (a field the user did not write)
        (FILAMENT, ["--spacing", "0"], "--spacing: must lie in [0.001, 100] mm; got 0.0"),
        (FILAMENT, ["--spacing", "20"], "--spacing: filaments[0]: has 2 vertices at spacing 20"),
        # before: "temperature: must exceed ..." (not the flag, raised while writing the run)
        (FILAMENT, ["--temperature", "20"], "--temperature: must exceed the start temperature 25"),
        (FILAMENT, ["--start-temperature", "200"], "--start-temperature: must be below the final"),
        (LATTICE.format(n=3), ["--temperature", "20"], "--temperature: must exceed the start"),
    ],
)
def test_options_that_do_not_apply_or_are_absurd_are_refused(
    tmp_path, capsys, text, flags, message
):
    out = tmp_path / "out"
    assert main(["simulate", str(_write(tmp_path, text)), "-o", str(out), *flags]) == EXIT_USAGE
    assert message in _error(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.toml"]


@pytest.mark.parametrize("command", ["validate", "simulate", "gcode"])
@pytest.mark.parametrize(
    ("blob", "message"),
    [
        ("schema_version = 1\nname = 'é'\n[lattice]\n".encode("latin-1"), "is not UTF-8 text"),
        (LATTICE.format(n=500).encode(), "lattice: too large: about 5,240,000 rod nodes"),
        (LATTICE.format(n="1e20").encode(), "lattice.n: must be a whole number"),
        (FILAMENT.replace("spacing = 1.0", "speed = true").encode(), "speed: must be a number"),
    ],
)
def test_every_command_refuses_the_same_designs(tmp_path, capsys, command, blob, message):
    path = tmp_path / "design.toml"
    path.write_bytes(blob)
    out = tmp_path / ("out.gcode" if command == "gcode" else "out")
    argv = [command, str(path)] + ([] if command == "validate" else ["-o", str(out)])
    assert main(argv) == EXIT_USAGE
    assert message in _error(capsys)
    assert not out.exists()


def test_validate_checks_a_machine_like_gcode(tmp_path, capsys):
    design = _write(tmp_path, FILAMENT)
    machine = tmp_path / "machine.toml"
    machine.write_text("[machine]\nenvelope_max = [5.0, 5.0, 5.0]\n")
    assert main(["validate", str(design)]) == EXIT_OK
    assert "rod nodes" in capsys.readouterr().out
    assert main(["validate", str(design), "--machine", str(machine)]) == EXIT_USAGE
    assert "machine limits" in _error(capsys)
    out = tmp_path / "x.gcode"
    assert main(["gcode", str(design), "-o", str(out), "--machine", str(machine)]) == EXIT_USAGE
    assert "machine limits" in _error(capsys)
    machine.write_text('[machine]\nmax_feed = "50"\n')
    assert main(["validate", str(design), "--machine", str(machine)]) == EXIT_USAGE
    assert "max_feed" in _error(capsys)


@pytest.mark.parametrize("cure", ["-5", "nan", "inf", "1e9", "3600.5"])
def test_gcode_cure_must_be_a_dwell_within_an_hour(tmp_path, capsys, cure):
    # before: "layer_cure_s: must be >= 0 s; got nan" (a library argument, not the flag), and
    # --cure 1e9 (32 years of dwell per layer) was written
    out = tmp_path / "x.gcode"
    argv = ["gcode", str(_write(tmp_path, FILAMENT)), "-o", str(out), "--cure", cure]
    assert main(argv) == EXIT_USAGE
    assert _error(capsys) == (
        f"--cure: must be a UV dwell per layer in [0, 3600] s; got {float(cure):g} s"
    )
    assert not out.exists()
    argv[-1] = "3600"
    assert main(argv) == EXIT_OK and "3600 s" in out.read_text()
    capsys.readouterr()


@pytest.mark.parametrize(
    ("argv", "message", "help_of"),
    [
        (
            ["simulate", "d.toml", "-o", "x", "--steps", "abc"],
            "argument --steps: invalid int value: 'abc'",
            "rotomorph simulate",
        ),
        (["design", "d.toml"], "argument COMMAND: invalid choice: 'design'", "rotomorph"),
    ],
)
def test_argument_errors_say_rotomorph_once_and_where_help_is(capsys, argv, message, help_of):
    # before: "rotomorph: error: rotomorph simulate: argument --steps: ... (see --help)"
    assert main(argv) == EXIT_USAGE
    err = _error(capsys)
    assert err.startswith(message), err
    assert err.endswith(f"(see {help_of} --help)"), err
