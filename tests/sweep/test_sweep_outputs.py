"""Any Executor runs a sweep; per-run HDF5 files on request; the closed form agrees with the
materials layer; figures are drawn from the table."""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np

from rotomorph.io.results import read_results
from rotomorph.sweep import parse_sweep, run_sweep
from rotomorph.sweep.figures import plot_sweep
from rotomorph.sweep.store import RunStore

DESIGN = {
    "schema_version": 1,
    "filaments": [
        {
            "speed": 3.0,
            "rotation_number": 0.25,
            "radius": 0.3,
            "spacing": 1.0,
            "segments": [{"kind": "line", "length": 8.0}],
        }
    ],
}


def test_thread_pool_and_per_run_hdf5(tmp_path):
    sweep = parse_sweep(
        {
            "schema_version": 1,
            "design": DESIGN,
            "outputs": ["end_to_end_ratio", "morphology"],
            "settings": {"steps": 2},
            "hdf5": True,
            "parameters": [{"path": "filaments[0].rotation_number", "values": [0.1, 1.0]}],
        }
    )
    with ThreadPoolExecutor(1) as pool:
        result = run_sweep(sweep, tmp_path / "out", executor=pool)
    rows = result.table.to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok"]
    store = RunStore(tmp_path / "out")
    for r in rows:
        run = read_results(store.results_path(r["run_id"]))
        assert run.metadata["run_id"] == r["run_id"]
        assert run.programs and "arc_length" in run.static  # the self-describing run data
        first, last = run.positions[0], run.positions[-1]
        ratio = np.linalg.norm(last[-1] - last[0]) / np.linalg.norm(first[-1] - first[0])
        assert abs(ratio - r["end_to_end_ratio"]) < 1e-12


def test_closed_form_matches_the_materials_layer(tmp_path):
    from rotomorph.materials.calibrate import filament_shapes
    from rotomorph.materials.natural import FilamentModel

    omega = [0.06, 0.25, 1.0, 2.0]
    sweep = parse_sweep(
        {
            "schema_version": 1,
            "design": DESIGN,
            "outputs": ["end_to_end_ratio", "morphology", "helix_pitch"],
            "settings": {"method": "closed_form", "spacing": 0.05},
            "parameters": [
                {"path": "filaments[0].active_fraction", "values": [0.5, 1.0]},
                {"path": "filaments[0].rotation_number", "name": "omega_star", "values": omega},
            ],
        }
    )
    with ThreadPoolExecutor(2) as pool:
        table = run_sweep(sweep, tmp_path / "cf", executor=pool).table
    rows = table.to_pylist()
    for fraction in (0.5, 1.0):
        expected = filament_shapes(FilamentModel(), np.array(omega), fraction)
        got = [r for r in rows if r["filaments[0].active_fraction"] == fraction]
        for r, shape in zip(got, expected, strict=True):
            # the sweep evaluates the discretised print program's field at 175 °C (relative
            # differences 4e-4 at 0.1 mm vertices, 3e-4 at 0.05 mm, 2.5e-4 at 0.02 mm), the
            # materials layer the continuous filament at full actuation
            assert abs(r["end_to_end_ratio"] / shape.end_to_end_ratio - 1.0) < 1e-3
            assert r["morphology"] == shape.label
            assert r["physical"] is None and r["physical_reason"].startswith("closed form")
    figures = plot_sweep(
        table, ["filaments[0].active_fraction", "omega_star"], sweep.outputs, tmp_path / "figs"
    )
    assert {p.name for p in figures} == {
        "phase_diagram.png",
        "heatmap_end_to_end_ratio.png",
        "heatmap_helix_pitch.png",
    }
    assert all(p.stat().st_size > 5000 for p in figures)


def test_lattice_sweep_reports_the_runs_verdict(tmp_path):
    lattice = {"n": 3, "spacing": 5.0, "amplitude": 1.25, "pattern": "dome", "layers": 1}
    sweep = parse_sweep(
        {
            "schema_version": 1,
            "design": {"schema_version": 1, "lattice": lattice},
            "outputs": ["area_ratio", "gaussian_sign", "min_clearance", "stable"],
            "settings": {"steps": 2},
            "parameters": [{"path": "lattice.pattern", "values": ["dome", "saddle"]}],
        }
    )
    with ThreadPoolExecutor(1) as pool:
        rows = run_sweep(sweep, tmp_path / "lat", executor=pool).table.to_pylist()
    assert [r["status"] for r in rows] == ["ok", "ok"]
    for r in rows:
        assert isinstance(r["gaussian_sign"], int) and r["area_ratio"] > 0
        # overlapping filaments (no contact model) are never reported as physical
        if r["min_clearance"] < 1.0:
            reason = r["physical_reason"]
            assert r["physical"] is False and ("overlap" in reason or "pass through" in reason)
        else:
            assert r["physical"] is not False


def test_cli_on_a_dask_scheduler_address(tmp_path, capsys):
    import pytest

    distributed = pytest.importorskip("distributed")
    from rotomorph.cli import main
    from rotomorph.sweep import read_table

    path = tmp_path / "cf.toml"
    path.write_text(
        'schema_version = 1\noutputs = ["end_to_end_ratio", "morphology"]\n'
        "[design]\nschema_version = 1\n[[design.filaments]]\nspacing = 0.1\n"
        'segments = [{kind = "line", length = 8.0}]\n'
        '[settings]\nmethod = "closed_form"\n'
        '[[parameters]]\npath = "filaments[0].rotation_number"\nvalues = [0.06, 0.25, 1.0]\n'
    )
    with distributed.LocalCluster(
        n_workers=1, threads_per_worker=2, processes=False, dashboard_address=None
    ) as cluster:
        code = main(
            [
                "sweep",
                str(path),
                "-o",
                str(tmp_path / "out"),
                "--scheduler",
                cluster.scheduler_address,
            ]
        )
    assert code == 0, capsys.readouterr().err
    assert "3 ok" in capsys.readouterr().out
    rows = read_table(tmp_path / "out").to_pylist()
    # the same sweep on the local pool labels every run the same way (the labels themselves
    # follow the calibrated model: a coil at the lowest rotation, no coil at the highest)
    assert main(["sweep", str(path), "-o", str(tmp_path / "local"), "--workers", "1"]) == 0
    local = read_table(tmp_path / "local").to_pylist()
    assert [r["morphology"] for r in rows] == [r["morphology"] for r in local]
    assert rows[0]["morphology"] == "coil" and rows[-1]["morphology"] != "coil"
