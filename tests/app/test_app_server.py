"""The app without a browser: its files are the CLI's, byte for byte; edits are validated as
``rotomorph validate`` validates; requests that do not fit the page, a foreign ``Host`` and
oversized bodies get one line of text, never a traceback; the command's arguments are checked."""

from __future__ import annotations

import io
import zipfile
from pathlib import Path

import pytest
import tomli_w

from rotomorph.cli import main
from rotomorph.errors import InvalidParameterError

pytest.importorskip("dash")

from rotomorph.app import editing, files
from rotomorph.io.designfile import load_design
from rotomorph.io.machine import load_machine_profile
from rotomorph.io.tomlfile import decode_toml_bytes

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"


def _data(name: str) -> dict:
    path = EXAMPLES / "designs" / f"{name}.toml"
    return decode_toml_bytes(path.read_bytes(), path.name)


@pytest.mark.parametrize("machine", [None, "klipper.toml", "aerotech_a3200_nordson.toml"])
def test_gcode_and_controller_files_are_the_clis_byte_for_byte(tmp_path, machine, capsys):
    data = editing.set_field(_data("composite_rotation"), "filaments[0].speed", 2.5)
    design, error = editing.check(data)
    assert error is None
    path = tmp_path / "d.toml"
    path.write_bytes(files.design_bytes(data))  # the page's "download design"
    args = ["gcode", str(path), "-o", str(tmp_path / "cli.gcode")]
    args += ["--machine-config", str(tmp_path / "cfg")]
    if machine is None:
        profile = files.machine_profile("builtin:aerotech", [], None)
    else:
        profile = load_machine_profile(EXAMPLES / "machines" / machine)
        args += ["--machine", str(EXAMPLES / "machines" / machine)]
    assert main(args) == 0
    program, config = files.gcode_bytes(design, profile)
    assert program == (tmp_path / "cli.gcode").read_bytes()
    written = {p.name: p.read_bytes() for p in (tmp_path / "cfg").iterdir()}
    assert config == written and config
    with zipfile.ZipFile(io.BytesIO(files.controller_zip(config))) as archive:
        assert {n: archive.read(n) for n in archive.namelist()} == written


def test_the_design_file_keeps_unset_values_unset(tmp_path):
    data = _data("lattice_dome")
    path = tmp_path / "d.toml"
    path.write_bytes(files.design_bytes(data))
    assert (
        load_design(path).sha256() == load_design(EXAMPLES / "designs/lattice_dome.toml").sha256()
    )
    assert "nozzle" not in decode_toml_bytes(path.read_bytes(), "d.toml")
    bad = editing.set_field(data, "lattice.n", 1)
    with pytest.raises(InvalidParameterError, match=r"^lattice\.n: "):
        files.design_bytes(bad)


def test_an_uploaded_machine_profile_reads_as_the_cli_reads_the_file(tmp_path):
    for path in sorted((EXAMPLES / "machines").glob("*.toml")):
        raw = path.read_bytes()
        if b"header_file" in raw or b"footer_file" in raw:  # names a file: refused from a page
            with pytest.raises(InvalidParameterError, match="give header_lines inline"):
                files.parse_machine_bytes(raw, path.name)
            continue
        assert files.parse_machine_bytes(raw, path.name) == load_machine_profile(path)
    with pytest.raises(InvalidParameterError, match="header_file"):
        files.parse_machine_bytes(b'[machine]\nheader_file = "/etc/passwd"\n', "m.toml")
    with pytest.raises(InvalidParameterError, match="machine: unknown machine choice"):
        files.machine_profile("example:../../etc/passwd", [], None)


def test_edits_are_validated_with_the_clis_one_line_error(tmp_path, capsys):
    data = _data("composite_rotation")
    assert editing.parse_value("2") == 2 and editing.parse_value(" 2.5 ") == 2.5
    assert editing.parse_value("") is None and editing.parse_value("nan") == "nan"
    assert editing.parse_value("true") is True and editing.parse_value("abc") == "abc"
    for path, value in [
        ("filaments[0].speed", -2),
        ("filaments[0].speed", "abc"),
        ("filaments[0].segments[0].length", 0),
        ("name", "x\x1b[31m"),
    ]:
        bad = editing.set_field(data, path, value)
        design, (field, line) = editing.check(bad)
        assert design is None and editing.error_field(field) == path
        file = tmp_path / "bad.toml"
        file.write_text(tomli_w.dumps(bad), encoding="utf-8")
        capsys.readouterr()
        assert main(["validate", str(file)]) == 2
        assert capsys.readouterr().err.strip() == f"rotomorph: error: {line}"
    assert editing.get_field(editing.set_field(data, "name", None), "name") is None


def test_clicked_edges_make_a_custom_pattern():
    data = _data("lattice_dome")
    design, _ = editing.check(data)
    modes = editing.edge_modes(design.lattice)
    first = modes[0]
    other = "expanding" if first == "contracting" else "contracting"
    new = editing.set_edge(data, modes, 0, mode=other, speed="4.5")
    design2, error = editing.check(new)
    assert error is None
    assert editing.edge_modes(design2.lattice) == [other, *modes[1:]]
    assert design2.lattice.edge_speeds[0] == 4.5 and len(design2.lattice.edge_speeds) == len(modes)
    with pytest.raises(InvalidParameterError, match=r"^edge: "):
        editing.set_edge(data, modes, len(modes), mode=other, speed=None)
    with pytest.raises(InvalidParameterError, match=r"^mode: "):
        editing.set_edge(data, modes, 0, mode="<b>", speed=None)


@pytest.fixture(scope="module")
def client():
    from rotomorph.app.jobs import Sessions
    from rotomorph.app.server import create_app

    app, sessions = create_app(examples=EXAMPLES, sessions=Sessions(prewarm=False))
    yield app.server.test_client()
    sessions.close()


def _one_line(response) -> str:
    text = response.get_data(as_text=True)
    assert response.headers["Content-Type"].startswith("text/plain")
    assert text.count("\n") == 1 and "Traceback" not in text and "<" not in text
    return text


def test_the_page_loads_with_safe_headers(client):
    page = client.get("/")
    assert page.status_code == 200
    assert page.headers["X-Content-Type-Options"] == "nosniff"
    assert page.headers["X-Frame-Options"] == "DENY"
    layout = client.get("/_dash-layout").get_data(as_text=True)
    assert "lattice_dome" in layout and str(EXAMPLES) not in layout  # choices, not paths


def test_a_foreign_host_is_refused(client):
    response = client.get("/", headers={"Host": "rebound.example:8050"})
    assert response.status_code == 403
    assert "answers only to 127.0.0.1" in _one_line(response)


@pytest.mark.parametrize(
    "body, status",
    [
        ("garbage", 400),
        ('{"output": "no-such.children", "outputs": {}, "inputs": [], "changedPropIds": []}', 400),
        ("x" * 9_000_000, 413),
    ],
)
def test_requests_that_do_not_fit_get_one_line(client, body, status):
    response = client.post("/_dash-update-component", data=body, content_type="application/json")
    assert response.status_code == status
    _one_line(response)


def test_a_forged_session_id_is_refused(client):
    from rotomorph.app.jobs import Sessions

    with pytest.raises(InvalidParameterError, match=r"^session: "):
        Sessions().files("../../etc")
    deps = client.get("/_dash-dependencies").get_json()
    (cancel,) = [d for d in deps if d["inputs"] == [{"id": "cancel", "property": "n_clicks"}]]
    body = {
        "output": cancel["output"],
        "outputs": {"id": "job-status", "property": "children"},
        "inputs": [{"id": "cancel", "property": "n_clicks", "value": 1}],
        "state": [{"id": "sid", "property": "data", "value": "../../etc"}],
        "changedPropIds": ["cancel.n_clicks"],
    }
    response = client.post("/_dash-update-component", json=body)
    assert response.status_code == 400
    assert _one_line(response).startswith("rotomorph serve: session: ")


def test_files_outside_dashs_own_are_not_served(client):
    response = client.get("/_dash-component-suites/../../../../etc/passwd")
    assert response.status_code in (400, 404)
    _one_line(response)


def test_serve_arguments_are_checked(capsys):
    assert main(["serve", "--port", "70000", "--no-open"]) == 2
    assert (
        capsys.readouterr().err.strip() == "rotomorph: error: --port: must be 0..65535; got 70000"
    )
    assert main(["serve", "--examples", "/no/such/dir", "--no-open"]) == 2
    assert "--examples: /no/such/dir: no such folder" in capsys.readouterr().err
    from rotomorph.cli import build_parser

    args = build_parser().parse_args(["serve"])
    assert args.host == "127.0.0.1" and args.open is True
    assert args.prewarm is True  # a served session's worker warms up unless told not to
    assert build_parser().parse_args(["serve", "--no-prewarm"]).prewarm is False


def test_a_taken_port_is_a_one_line_error(capsys):
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        s.listen()
        port = s.getsockname()[1]
        assert main(["serve", "--port", str(port), "--no-open", "--examples", str(EXAMPLES)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("rotomorph: error: --host/--port: cannot listen")


def test_points_are_typed_as_x_y_z():
    assert editing.parse_field("filaments[0].start", "1, 2.5 3") == [1, 2.5, 3]
    assert editing.parse_field("filaments[0].start", "[1, 2, 3]") == [1, 2, 3]
    assert editing.parse_field("filaments[0].start", "1, x, 3") == "1, x, 3"  # stays text
    points = editing.parse_field("filaments[0].segments[1].points", "0,0,0\n1, 0, 0; 2 1 0")
    assert points == [[0, 0, 0], [1, 0, 0], [2, 1, 0]]
    assert editing.format_value(points) == "0, 0, 0\n1, 0, 0\n2, 1, 0"
    assert editing.parse_field("filaments[0].speed", "2") == 2  # other fields as before
    data = _data("composite_rotation")
    assert editing.set_field(data, "nozzle.diameter", None) is data  # no empty [nozzle] made
    bad = editing.set_field(data, "filaments[0].start", "1, x, 3")
    design, error = editing.check(bad)
    assert design is None and editing.error_field(error[0]) == "filaments[0].start"
    moved = editing.set_field(data, "filaments[0].start", [5.0, 6.0, 0.0])
    design, error = editing.check(moved)
    assert error is None
    assert list(design.filaments[0].to_program().points[0]) == [5.0, 6.0, 0.0]


def _without_sd(record):
    if isinstance(record, dict):
        return {k: _without_sd(v) for k, v in record.items() if k != "sd_calibration"}
    if isinstance(record, list):
        return [_without_sd(v) for v in record]
    return record


@pytest.mark.parametrize("name", ["composite_rotation", "lattice_dome"])
def test_the_nominal_prediction_is_the_banded_ones_without_its_band(name):
    from rotomorph.prediction.band import nominal_only
    from rotomorph.prediction.design import predict_design

    design, _ = editing.check(_data(name))
    full = predict_design(design)
    with nominal_only():
        quick = predict_design(design)
    assert "±" in " ".join(full.lines()) and "±" not in " ".join(quick.lines())
    assert _without_sd(quick.record()) == _without_sd(full.record())
