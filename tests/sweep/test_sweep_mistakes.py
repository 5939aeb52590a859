"""Sweep-file and command-line mistakes a newcomer makes: refused before any run or folder."""

from __future__ import annotations

import pytest

from rotomorph.cli import EXIT_USAGE, main
from rotomorph.errors import InvalidParameterError
from rotomorph.sweep import parse_sweep
from rotomorph.sweep.paths import check_path

DESIGN = {
    "schema_version": 1,
    "filaments": [{"speed": 1.0, "spacing": 1.0, "segments": [{"kind": "line", "length": 10.0}]}],
}


def sweep(path: str):
    return parse_sweep(
        {
            "schema_version": 1,
            "design": DESIGN,
            "outputs": ["end_to_end_ratio"],
            "parameters": [{"path": path, "values": [0.5, 1.0]}],
        }
    )


@pytest.mark.parametrize(
    ("path", "message"),
    [
        ("filaments[0].sped", r"filaments\[0\] has no field 'sped'; check its spelling"),
        ("filaments[3].speed", r"filaments has 1 element\(s\); index 3 is past it"),
        ("contact.friction", "the base design has no contact; add it"),
        ("filaments[0].segments[0].amplitude", "has no field 'amplitude'"),
    ],
)
def test_a_path_the_design_does_not_have_is_refused_at_once(path, message):
    # before: accepted, and every point of the sweep became an 'invalid' run (exit 0)
    with pytest.raises(InvalidParameterError, match=message) as err:
        sweep(path)
    assert err.value.field == "parameters[0].path"


@pytest.mark.parametrize(
    "path",
    ["filaments[0].speed", "filaments[*].rotation_number", "filaments.0.segments[0].length"],
)
def test_fields_the_base_design_leaves_at_their_default_can_be_swept(path):
    assert sweep(path).parameters[0].path == path


def test_check_path_looks_at_the_last_key_too():
    check_path({"lattice": {"amplitude": 1.0}}, "lattice.amplitude")
    with pytest.raises(InvalidParameterError, match="has no field 'amplitud'"):
        check_path({"lattice": {"amplitude": 1.0}}, "lattice.amplitud")


def _sweep_file(tmp_path, path="filaments[0].speed"):
    file = tmp_path / "sweep.toml"
    file.write_text(
        'schema_version = 1\noutputs = ["end_to_end_ratio"]\n'
        "[design]\nschema_version = 1\n[[design.filaments]]\nspacing = 1.0\n"
        'segments = [{kind = "line", length = 5.0}]\n'
        f'[[parameters]]\npath = "{path}"\nvalues = [1.0]\n'
    )
    return file


def test_cli_misspelt_path_exits_2_without_a_folder(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["sweep", str(_sweep_file(tmp_path, "filaments[0].sped")), "-o", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rotomorph: error: parameters[0].path: filaments[0].sped:"), err
    assert not out.exists()


@pytest.mark.parametrize(
    ("address", "reason"),
    [
        ("localhost", "missing port number"),  # before: a distributed traceback, exit 1
        ("http://127.0.0.1:8787", "unknown address scheme 'http'"),  # the dashboard
        ("tcp://host:port", "invalid literal"),
    ],
)
def test_cli_a_scheduler_that_is_not_an_address_exits_2(tmp_path, capsys, address, reason):
    out = tmp_path / "out"
    argv = ["sweep", str(_sweep_file(tmp_path)), "-o", str(out), "--scheduler", address]
    assert main(argv) == EXIT_USAGE
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    assert err.startswith(f"rotomorph: error: --scheduler: {address!r} is not a Dask scheduler")
    assert reason in err and "tcp://HOST:PORT" in err
    assert not out.exists()


def test_sweep_schema_errors_read_as_the_design_files_do():
    # before: "settings.steps: Input should be greater than or equal to 1"
    data = {
        "schema_version": 1,
        "design": DESIGN,
        "outputs": ["end_to_end_ratio"],
        "parameters": [{"path": "filaments[0].speed", "values": [1.0]}],
    }
    with pytest.raises(InvalidParameterError) as err:
        parse_sweep({**data, "settings": {"steps": 0}})
    assert str(err.value) == "settings.steps: must be >= 1; got 0"
    with pytest.raises(InvalidParameterError) as err:
        parse_sweep({**data, "settings": {"method": "fem"}})
    assert str(err.value) == "settings.method: must be 'rod' or 'closed_form'; got 'fem'"
