"""Sweep files, sampling, dotted paths and run ids (no runs computed)."""

from __future__ import annotations

import json

import numpy as np
import pytest

import rotomorph
from rotomorph.cli import main
from rotomorph.errors import InvalidDesignError, InvalidParameterError
from rotomorph.sweep import parse_sweep, resolve_run, sample_points, sweep_schema
from rotomorph.sweep.paths import parse_path, set_path

DESIGN = {
    "schema_version": 1,
    "filaments": [{"speed": 1.0, "spacing": 1.0, "segments": [{"kind": "line", "length": 10.0}]}],
}


def sweep(**over):
    data = {
        "schema_version": 1,
        "design": DESIGN,
        "outputs": ["end_to_end_ratio"],
        "parameters": [{"path": "filaments[0].speed", "values": [0.5, 1.0]}],
    }
    data.update(over)
    return parse_sweep(data)


def test_paths_parse_and_set():
    steps = ("filaments", 0, "segments", 2, "length")
    assert parse_path("filaments[0].segments[2].length") == steps
    assert parse_path("filaments.1.speed") == ("filaments", 1, "speed")
    assert parse_path("filaments[*].speed") == ("filaments", -1, "speed")
    two = {"filaments": [{"speed": 1.0}, {"speed": 2.0}]}
    assert set_path(two, "filaments[*].speed", 3.0) == {"filaments": [{"speed": 3.0}] * 2}
    assert two["filaments"][0]["speed"] == 1.0  # a copy
    with pytest.raises(InvalidParameterError, match=r"filaments\[2\].*index 2"):
        set_path(two, "filaments[2].speed", 1.0)
    with pytest.raises(InvalidParameterError, match="cannot read"):
        parse_path("filaments[0]..speed")


def test_grid_is_the_product_in_order():
    s = sweep(
        parameters=[
            {"path": "filaments[0].speed", "values": [0.5, 1.0]},
            {"path": "filaments[0].rotation_number", "range": {"start": 0, "stop": 1, "num": 3}},
        ]
    )
    points = sample_points(s)
    assert [tuple(p.values()) for p in points] == [
        (0.5, 0.0),
        (0.5, 0.5),
        (0.5, 1.0),
        (1.0, 0.0),
        (1.0, 0.5),
        (1.0, 1.0),
    ]


def test_latin_hypercube_stratifies_every_parameter_and_is_seeded():
    params = [
        {"path": "filaments[0].speed", "distribution": {"kind": "uniform", "low": 1, "high": 3}},
        {
            "path": "filaments[0].rotation_number",
            "distribution": {"kind": "loguniform", "low": 0.01, "high": 1.0},
        },
    ]
    s = sweep(parameters=params, sampling={"method": "latin_hypercube", "samples": 10, "seed": 3})
    pts = sample_points(s)
    v = np.array([p["filaments[0].speed"] for p in pts])
    w = np.array([p["filaments[0].rotation_number"] for p in pts])
    # one point in each tenth of each (log) range
    assert sorted(np.floor((v - 1) / 2 * 10).astype(int)) == list(range(10))
    assert sorted(np.floor(np.log10(w / 0.01) / 2 * 10).astype(int)) == list(range(10))
    assert sample_points(s) == pts
    other = sweep(parameters=params, sampling={"method": "latin_hypercube", "samples": 10})
    assert sample_points(other) != pts


def test_random_sampling_of_a_list_draws_its_values():
    s = sweep(
        parameters=[{"path": "filaments[0].speed", "values": [0.5, 2.0]}],
        sampling={"method": "random", "samples": 40, "seed": 1},
    )
    drawn = [p["filaments[0].speed"] for p in sample_points(s)]
    assert set(drawn) == {0.5, 2.0}


def test_run_id_hashes_the_resolved_design_settings_and_version(monkeypatch):
    s = sweep()
    a = resolve_run(s, {"filaments[0].speed": 1.0})
    # the same design spelled differently (a default written out) is the same run
    b = resolve_run(s, {"filaments[0].radius": 0.3, "filaments[0].speed": 1.0})
    assert a.run_id == b.run_id and len(a.run_id) == 64
    assert resolve_run(s, {"filaments[0].speed": 1.5}).run_id != a.run_id
    steps = sweep(settings={"steps": 3})
    assert resolve_run(steps, {"filaments[0].speed": 1.0}).run_id != a.run_id
    monkeypatch.setattr(rotomorph, "__version__", "99.0")
    assert resolve_run(s, {"filaments[0].speed": 1.0}).run_id != a.run_id


def test_invalid_point_is_resolved_with_its_error():
    spec = resolve_run(sweep(), {"filaments[0].speed": 0.0})
    assert spec.error is not None
    assert spec.error["type"] == "InvalidDesignError"
    assert spec.error["diagnostics"] == {"field": "filaments[0].speed"}


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"outputs": ["area_ratio"]}, "outputs[0]"),
        ({"outputs": ["no_such_metric"]}, "outputs[0]"),
        ({"sampling": {"method": "random"}}, "sampling"),
        ({"sampling": {"method": "grid", "samples": 3}}, "sampling"),
        (
            {"parameters": [{"path": "filaments[0].speed", "distribution": {"kind": "uniform"}}]},
            "parameters[0].distribution",
        ),
        (
            {
                "parameters": [
                    {
                        "path": "filaments[0].speed",
                        "distribution": {"kind": "uniform", "low": 1, "high": 2},
                    }
                ]
            },
            "<sweep>",
        ),
        ({"parameters": [{"path": "filaments[0].speed"}]}, "parameters[0]"),
        ({"settings": {"method": "magic"}}, "settings.method"),
        ({"bogus": 1}, "bogus"),
    ],
)
def test_bad_sweep_files_name_the_field(change, field):
    with pytest.raises(InvalidParameterError) as err:
        sweep(**change)
    assert err.value.field == field


def test_bad_base_design_is_reported_under_design():
    bad = {**DESIGN, "filaments": [{"speed": -1.0, "segments": [{"kind": "line", "length": 1}]}]}
    with pytest.raises(InvalidDesignError) as err:
        sweep(design=bad)
    assert err.value.field == "design.filaments[0].speed"


def test_multi_filament_outputs_must_name_the_filament():
    two = {**DESIGN, "filaments": DESIGN["filaments"] * 2}
    with pytest.raises(InvalidParameterError, match=r"filaments\[0\].end_to_end_ratio"):
        sweep(design=two)
    assert sweep(design=two, outputs=["filaments[1].end_to_end_ratio"]).outputs


def test_schema_is_json_and_names_every_section():
    schema = sweep_schema()
    json.dumps(schema)
    assert {"design", "parameters", "sampling", "settings", "outputs"} <= set(schema["properties"])


def test_cli_reports_bad_input_with_exit_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(
        'schema_version = 1\noutputs = ["nope"]\n'
        "[design]\nschema_version = 1\n[[design.filaments]]\n"
        'segments = [{kind = "line", length = 5.0}]\n'
        '[[parameters]]\npath = "filaments[0].speed"\nvalues = [1.0]\n'
    )
    assert main(["sweep", str(path), "-o", str(tmp_path / "out")]) == 2
    assert "outputs[0]" in capsys.readouterr().err
    assert main(["sweep", str(tmp_path / "missing.toml"), "-o", str(tmp_path / "o")]) == 2
    assert main(["sweep", "--schema"]) == 0
    assert '"parameters"' in capsys.readouterr().out


def test_truncated_normal_stays_in_its_bounds_and_centres_on_the_mean():
    dist = {"kind": "normal", "mean": 2.0, "std": 0.5, "low": 1.5, "high": 3.0}
    s = sweep(
        parameters=[{"path": "filaments[0].speed", "distribution": dist}],
        sampling={"method": "latin_hypercube", "samples": 1000, "seed": 0},
    )
    v = np.array([p["filaments[0].speed"] for p in sample_points(s)])
    assert v.min() >= 1.5 and v.max() <= 3.0
    # mean of N(2, 0.5) truncated to [1.5, 3]: 2 + 0.5 (φ(-1) - φ(2)) / (Φ(2) - Φ(-1)) = 2.11482
    assert abs(v.mean() - 2.11482) < 2e-3
