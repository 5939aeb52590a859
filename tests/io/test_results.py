"""HDF5 results and summary.json: round trips, units, validation, atomicity."""

from __future__ import annotations

import dataclasses
import json
import os

import h5py
import numpy as np
import pytest

from rotomorph.design.network import Network
from rotomorph.errors import InvalidParameterError
from rotomorph.io.results import (
    RunResults,
    read_results,
    read_summary,
    summarize,
    to_jsonable,
    write_results,
    write_summary,
)


@pytest.fixture
def run():
    rng = np.random.default_rng(0)
    net = Network.chain(np.c_[np.arange(6.0), np.zeros(6), np.zeros(6)])
    steps = 4
    positions = net.nodes[None] + rng.normal(scale=0.1, size=(steps, 6, 3))
    scalars = {
        "actuation": np.linspace(0, 1, steps),
        "energy": np.array([0.0, 1.5, 2.5, np.nan]),
        "iterations": np.array([0, 5, 7, 9]),
        "area_ratio": np.array([1.0, 1.1, 1.2, 1.3]),
        "gaussian_sign": np.array([0, 1, 1, 1]),
        "characteristic_curvature": np.array([0.0, 0.01, 0.02, 0.03]),
    }
    fields = {"curvature_change": rng.normal(size=(steps, 6))}
    design = {"lattice": {"n": 5, "speed": 3.0}, "name": "dome", "cells": [1, 2]}
    return net, positions, scalars, fields, design


def test_round_trip(tmp_path, run):
    net, positions, scalars, fields, design = run
    path = write_results(
        tmp_path / "run.h5",
        design=design,
        edges=net.edges,
        branch=net.branch,
        positions=positions,
        scalars=scalars,
        fields=fields,
        units={"curvature_change": "1"},
        metadata={"run_id": "abc", "version": "0.1.0"},
    )
    res = read_results(path)
    assert isinstance(res, RunResults)
    assert res.design == design
    np.testing.assert_array_equal(res.edges, net.edges)
    np.testing.assert_array_equal(res.branch, net.branch)
    np.testing.assert_array_equal(res.positions, positions)
    assert res.n_steps == 4
    assert set(res.scalars) == set(scalars)
    for name, value in scalars.items():
        np.testing.assert_array_equal(res.scalars[name], value)
    np.testing.assert_array_equal(res.fields["curvature_change"], fields["curvature_change"])
    assert res.units["positions"] == "mm"
    assert res.units["energy"] == "N*mm"
    assert res.units["characteristic_curvature"] == "1/mm"
    assert res.metadata == {"run_id": "abc", "version": "0.1.0"}
    with pytest.raises(dataclasses.FrozenInstanceError):
        res.positions = None  # type: ignore[misc]
    with pytest.raises(ValueError):
        res.positions[0, 0, 0] = 1.0
    assert os.listdir(tmp_path) == ["run.h5"]


def test_file_layout_is_self_describing(tmp_path, run):
    net, positions, scalars, _, design = run
    path = write_results(
        tmp_path / "r.h5",
        design=json.dumps(design),
        edges=net.edges,
        branch=None,
        positions=positions,
        scalars=scalars,
    )
    with h5py.File(path, "r") as h5:
        assert h5.attrs["format"] == "rotomorph.results"
        assert json.loads(h5.attrs["design"]) == design
        assert h5["steps/positions"].shape == (4, 6, 3)
        assert h5["steps/positions"].attrs["units"] == "mm"
        assert h5["steps/scalars/area_ratio"].attrs["units"] == "1"
        assert not h5["topology/branch"][()].any()


def test_single_step_and_large_design(tmp_path, run):
    net, positions, _, _, _ = run
    design = {"table": list(range(30000))}
    path = write_results(
        tmp_path / "one.h5",
        design=design,
        edges=net.edges,
        branch=net.branch,
        positions=positions[0],
        scalars={"actuation": [0.5]},
    )
    res = read_results(path)
    assert res.positions.shape == (1, 6, 3)
    assert res.design == design


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"scalars": {"energy": np.zeros(3)}}, "scalars['energy']"),
        ({"scalars": {"wobble": np.zeros(4)}}, "units"),
        ({"positions": np.zeros((4, 6, 2))}, "positions"),
        ({"edges": np.array([[0, 9]])}, "edges"),
        ({"branch": np.zeros(5, bool)}, "branch"),
        ({"fields": {"k": np.zeros((3, 6))}, "units": {"k": "1/mm"}}, "fields['k']"),
        ({"design": "{not json"}, "design"),
        ({"metadata": {"x": object()}}, "value"),
    ],
)
def test_invalid_input_names_the_field_and_writes_nothing(tmp_path, run, change, field):
    net, positions, scalars, _, design = run
    kwargs = dict(
        design=design, edges=net.edges, branch=net.branch, positions=positions, scalars=scalars
    )
    kwargs.update(change)
    with pytest.raises(InvalidParameterError) as info:
        write_results(tmp_path / "bad.h5", **kwargs)
    assert info.value.field == field
    assert os.listdir(tmp_path) == []


def test_read_rejects_foreign_file(tmp_path):
    with h5py.File(tmp_path / "other.h5", "w") as h5:
        h5["x"] = 1
    with pytest.raises(InvalidParameterError, match=r"not a rotomorph\.results"):
        read_results(tmp_path / "other.h5")


def test_summary_round_trip(tmp_path, run):
    net, positions, scalars, _, design = run
    res = read_results(
        write_results(
            tmp_path / "run.h5",
            design=design,
            edges=net.edges,
            branch=net.branch,
            positions=positions,
            scalars=scalars,
        )
    )
    summary = summarize(res)
    assert summary["n_steps"] == 4 and summary["n_nodes"] == 6 and summary["n_edges"] == 5
    assert summary["end_of_ramp"]["area_ratio"] == pytest.approx(1.3)
    assert summary["end_of_ramp"]["energy"] is None  # NaN becomes null: strict JSON
    assert "final" not in summary  # the last state is a result only if it is physical
    assert summary["physical"]["verdict"] == "unknown"  # nothing assessed: never "fine"
    path = write_summary(tmp_path / "summary.json", summary)
    text = path.read_text()
    assert "NaN" not in text
    assert read_summary(path) == json.loads(text) == summary


def test_to_jsonable_converts_numpy():
    out = to_jsonable({"a": np.float32(1.5), "b": np.arange(3), "c": (np.True_, np.inf)})
    assert out == {"a": 1.5, "b": [0, 1, 2], "c": [True, None]}
    assert json.dumps(out)


def test_static_arrays_and_print_programs_round_trip(tmp_path, run):
    from rotomorph.design.program import PrintProgram
    from rotomorph.io.results import program_record

    net, positions, scalars, _, design = run
    pts = np.c_[np.linspace(0, 5, 6), np.zeros(6), np.zeros(6)]
    prog = PrintProgram(points=pts, speed=np.full(6, 3.0), nozzle_angle=np.linspace(0, 1, 6))
    static = {
        "arc_length": np.linspace(0, 5, 6),
        "radius": np.full(5, 0.3),
        "filament_id": np.zeros(6, dtype=int),
    }
    path = write_results(
        tmp_path / "r.h5",
        design=design,
        edges=net.edges,
        branch=net.branch,
        positions=positions,
        scalars=scalars,
        fields={"active_normal": np.tile([0.0, 0.0, 1.0], (4, 5, 1))},
        static=static,
        programs=[program_record(prog, "w*=0.25")],
        metadata={"physical": {"verdict": "no", "reason": "filaments overlap"}},
    )
    res = read_results(path)
    np.testing.assert_array_equal(res.static["arc_length"], static["arc_length"])
    assert res.units["arc_length"] == "mm" and res.units["radius"] == "mm"
    assert res.units["active_normal"] == "1" and res.static["filament_id"].dtype.kind == "i"
    (p,) = res.programs
    np.testing.assert_array_equal(p["points"], pts)
    assert p["name"] == "w*=0.25" and p["radius"] == 0.3 and p["active_material"] == "lce"
    with h5py.File(path, "r") as h5:
        assert h5.attrs["physical"] == "no" and h5.attrs["physical_reason"] == "filaments overlap"
        assert h5["programs/0000/speed"].attrs["units"] == "mm/s"
        assert h5["programs/0000"].attrs["radius_units"] == "mm"
    with pytest.raises(InvalidParameterError) as info:
        write_results(
            tmp_path / "bad.h5",
            design=design,
            edges=net.edges,
            branch=net.branch,
            positions=positions,
            scalars=scalars,
            static={"radius": np.zeros(3)},
        )
    assert info.value.field == "static['radius']"


def test_version_1_files_still_read(tmp_path, run):
    net, positions, scalars, _, design = run
    path = write_results(
        tmp_path / "old.h5",
        design=design,
        edges=net.edges,
        branch=net.branch,
        positions=positions,
        scalars=scalars,
    )
    with h5py.File(path, "a") as h5:  # what version 1 wrote: no static, no programs
        del h5["static"], h5["programs"]
        h5.attrs["format_version"] = 1
    res = read_results(path)
    assert res.static == {} and res.programs == () and res.n_steps == 4


def test_summary_of_a_run_in_memory_gives_every_scalar_its_unit(run):
    # before: summary.json of `rotomorph simulate` listed units only for the fields given
    # explicitly (curvature, positions, ...), none for temperature, energy, lowest_eigenvalue
    # or min_clearance, whose values it reports under initial / end_of_ramp
    net, positions, scalars, fields, design = run
    res = RunResults(
        design=design,
        edges=net.edges,
        branch=net.branch,
        positions=positions,
        scalars={**scalars, "temperature": np.linspace(25.0, 175.0, 4)},
        fields=fields,
        units={"curvature_change": "1"},
        metadata={},
    )
    units = summarize(res)["units"]
    assert set(summarize(res)["end_of_ramp"]) <= set(units)
    assert units["temperature"] == "degC" and units["energy"] == "N*mm"
    assert units["positions"] == "mm" and units["curvature_change"] == "1"
