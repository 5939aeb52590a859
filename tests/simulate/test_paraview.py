"""ParaView files of real runs, read back by VTK's own XML readers (what ParaView uses) and by
meshio: one set of array names with units for a filament run and a lattice run, no NaN at chain
ends or junctions, and a Janus tube surface whose ``active`` flag is the active half."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import meshio
import numpy as np
import pytest

try:
    import tomllib
except ImportError:  # Python 3.10
    import tomli as tomllib  # type: ignore[no-redef]

import rotomorph
from rotomorph.simulate.outputs import as_run
from rotomorph.simulate.paraview import TUBE_FACETS, write_vtk
from rotomorph.simulate.run_data import describe_run

ROOT = Path(__file__).resolve().parents[2]

#: A filament printed curved (a sinusoid, its active side flipping at the inflections).
FILAMENTS = """
schema_version = 1
name = "two filaments"
[[filaments]]
name = "sinusoid"
speed = 3.0
active_side = "outer"
flip_length = 0.5
start = [0.0, 0.0, 0.0]
spacing = 0.25
segments = [{ kind = "sinusoid", amplitude = 1.25, wavelength = 5.0, periods = 2 }]
"""

#: A filament printed straight while the nozzle turns (it heats into a helix).
STRAIGHT = """
schema_version = 1
name = "straight"
[[filaments]]
name = "helix"
speed = 3.0
rotation_number = 0.25
spacing = 0.25
segments = [{ kind = "line", length = 20.0 }]
"""

LATTICE = """
schema_version = 1
name = "small dome"
[lattice]
n = 3
spacing = 5.0
amplitude = 1.25
ghost_nodes = 6
pattern = "dome"
centre = "central_cells"
layers = 3
layer_height = 0.6
speed = 3.0
"""


def _run(text: str):
    design = rotomorph.parse_design(tomllib.loads(text))
    return describe_run(as_run(rotomorph.simulate(design, steps=2)))


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    out = {}
    for kind, text in (("filament", FILAMENTS), ("lattice", LATTICE)):
        results = _run(text)
        folder = tmp_path_factory.mktemp(kind)
        write_vtk(results, folder)
        out[kind] = (results, folder)
    return out


def _read(vtk, path: Path):
    poly = path.suffix == ".vtp"
    reader = vtk.vtkXMLPolyDataReader() if poly else vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfPoints() > 0, f"VTK read nothing from {path.name}"
    return data


def _arrays(vtk, data) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    from vtk.util.numpy_support import vtk_to_numpy

    def grab(fields):
        return {
            fields.GetArrayName(i): vtk_to_numpy(fields.GetArray(i))
            for i in range(fields.GetNumberOfArrays())
        }

    return grab(data.GetPointData()), grab(data.GetCellData())


def _last(folder: Path, stem: str, suffix: str) -> Path:
    return sorted(folder.glob(f"{stem}_*{suffix}"))[-1]


def test_one_set_of_names_with_units_across_run_kinds(runs, vtk):
    names = {}
    for kind, (_, folder) in runs.items():
        for stem, suffix in (("morphing", ".vtp"), ("segments", ".vtu"), ("janus", ".vtp")):
            point, cell = _arrays(vtk, _read(vtk, _last(folder, stem, suffix)))
            names[kind, stem] = (set(point), set(cell))
            for name, values in {**point, **cell}.items():
                if values.dtype.kind == "f" and name != "Normals":
                    assert name.endswith("]") and " [" in name, f"{name!r} carries no unit"
    for stem in ("morphing", "segments", "janus"):
        assert names["filament", stem] == names["lattice", stem], stem
    point, cell = names["lattice", "janus"]
    expected_point = {"curvature [1/mm]", "printed_curvature [1/mm]", "twist [1/mm]", "s [mm]",
                      "relative_curvature_change [1]", "Normals"}  # fmt: skip
    assert expected_point <= point
    assert {"active", "interface_angle [rad]", "radius [mm]", "active_normal [1]"} <= cell
    seg_point, seg_cell = names["lattice", "segments"]
    assert expected_point - {"Normals"} <= seg_point and "interface_angle [rad]" in seg_cell


def test_no_nan_and_ends_and_junctions_take_their_neighbours(runs, vtk):
    for kind, (results, folder) in runs.items():
        for path in sorted(folder.glob("*.vt?")):
            point, cell = _arrays(vtk, _read(vtk, path))
            for name, values in {**point, **cell}.items():
                assert np.isfinite(values).all(), f"{kind} {path.name}: NaN in {name!r}"
        point, _ = _arrays(vtk, _read(vtk, _last(folder, "segments", ".vtu")))
        edges = results.edges
        degree = np.bincount(edges.ravel(), minlength=results.positions.shape[1])
        special = np.flatnonzero((degree != 2) | (results.branch if results.branch is not None
                                                   else np.zeros(len(degree), bool)))  # fmt: skip
        assert len(special) >= 2
        for name in ("curvature [1/mm]", "twist [1/mm]", "relative_curvature_change [1]"):
            v = point[name]
            for node in special:
                nbrs = np.r_[edges[edges[:, 0] == node, 1], edges[edges[:, 1] == node, 0]]
                expected = np.mean(v[nbrs])
                assert v[node] == pytest.approx(expected, rel=1e-12, abs=1e-15), (kind, name)
        if kind == "lattice":
            assert results.branch is not None and results.branch.sum() == 9  # junctions checked


def test_a_run_printed_straight_has_the_same_names_but_no_relative_change(runs, vtk, tmp_path):
    results = _run(STRAIGHT)
    write_vtk(results, tmp_path)
    for stem, suffix in (("morphing", ".vtp"), ("segments", ".vtu"), ("janus", ".vtp")):
        point, cell = _arrays(vtk, _read(vtk, _last(tmp_path, stem, suffix)))
        other, other_cell = _arrays(vtk, _read(vtk, _last(runs["filament"][1], stem, suffix)))
        assert set(point) == set(other) - {"relative_curvature_change [1]"}
        assert set(cell) == set(other_cell)
        assert all(np.isfinite(v).all() for v in {**point, **cell}.values())


def test_curvature_is_the_runs_own(runs):
    """The ParaView curvature is the run's: the filament's stored κ, the lattice's stored
    (κ − κ_i)/κ_i, at every node where the run defines them."""
    for kind, (results, folder) in runs.items():
        mesh = meshio.read(_last(folder, "segments", ".vtu"))
        stored = results.fields["curvature" if kind == "filament" else "relative_curvature_change"]
        got = mesh.point_data[
            "curvature [1/mm]" if kind == "filament" else "relative_curvature_change [1]"
        ].reshape(-1)
        ok = np.isfinite(stored[-1])
        assert ok.sum() > 0.8 * len(ok)
        np.testing.assert_allclose(got[ok], stored[-1][ok], rtol=1e-12, atol=1e-12)
        np.testing.assert_array_equal(mesh.cells_dict["line"], results.edges)


def test_janus_tube_surface_flags_the_active_half(runs, vtk):
    from vtk.util.numpy_support import vtk_to_numpy

    for results, folder in runs.values():
        data = _read(vtk, _last(folder, "janus", ".vtp"))
        pts = vtk_to_numpy(data.GetPoints().GetData()).astype(float)
        polys = vtk_to_numpy(data.GetPolys().GetConnectivityArray()).reshape(-1, 4)
        _, cell = _arrays(vtk, data)
        edges, k = results.edges, TUBE_FACETS
        assert len(polys) == len(edges) * k
        seg = cell["segment_id"]
        np.testing.assert_array_equal(seg, np.repeat(np.arange(len(edges)), k))
        active = cell["active"]
        assert set(np.unique(active)) == {0, 1}
        # half of every segment's facets are active (active fraction 1/2) ...
        np.testing.assert_array_equal(active.reshape(-1, k).sum(axis=1), k // 2)
        # ... those whose outward direction points along the stored normal toward the active half
        pos = results.positions[-1]
        t = pos[edges[seg, 1]] - pos[edges[seg, 0]]
        t /= np.linalg.norm(t, axis=1)[:, None]

        def across(v, t=t):  # the part of v in the segment's cross-section
            return v - np.einsum("ij,ij->i", v, t)[:, None] * t

        centre = pts[polys].mean(axis=1)
        outward = across(centre - 0.5 * (pos[edges[seg, 0]] + pos[edges[seg, 1]]))
        normal = across(results.fields["active_normal"][-1][seg])
        side = np.einsum("ij,ij->i", outward, normal)
        assert np.all(side[active == 1] > 0) and np.all(side[active == 0] < 0)
        # the facets are a tube of the filament's radius around the segment (outward normals)
        a, b = pts[polys[:, 1]] - pts[polys[:, 0]], pts[polys[:, 3]] - pts[polys[:, 0]]
        assert np.all(np.einsum("ij,ij->i", np.cross(a, b), outward) > 0)
        radius = results.static["radius"][seg]
        corner = pts[polys[:, 0]] - pos[edges[seg, 0]]
        perp = corner - np.einsum("ij,ij->i", corner, t)[:, None] * t
        np.testing.assert_allclose(np.linalg.norm(perp, axis=1), radius, rtol=2e-2)


def test_pvd_series_play_the_ramp(runs):
    import xml.etree.ElementTree as ET

    for results, folder in runs.values():
        for stem in ("morphing", "segments", "janus"):
            sets = ET.parse(folder / f"{stem}.pvd").getroot().iter("DataSet")
            times = [float(d.get("timestep")) for d in sets]
            np.testing.assert_allclose(times, results.scalars["temperature"])


def test_show_janus_script_is_valid_python_naming_the_files(runs):
    for _, folder in runs.values():
        text = (folder / "show_janus.py").read_text(encoding="utf-8")
        compile(text, "show_janus.py", "exec")
        assert '"janus.pvd"' in text and '("CELLS", "active")' in text


@pytest.mark.referee
def test_show_janus_runs_in_paraview(runs, tmp_path):
    """ParaView's own pvbatch runs the script and renders the two halves (not in CI: Debian's
    ParaView is about 540 MB; ``apt-get install python3-paraview`` to run it)."""
    pvbatch = shutil.which("pvbatch")
    if pvbatch is None:
        pytest.skip("ParaView's pvbatch is not installed (apt-get install python3-paraview)")
    from PIL import Image

    for kind, (_, folder) in runs.items():
        work = tmp_path / kind
        shutil.copytree(folder, work)
        env = dict(os.environ, PYTHONPATH="")  # ParaView's own Python modules only
        command = [pvbatch, "--force-offscreen-rendering", str(work / "show_janus.py"),
                   "--screenshot"]  # fmt: skip
        if not os.environ.get("DISPLAY") and shutil.which("xvfb-run"):
            command = ["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", *command]
        proc = subprocess.run(command, capture_output=True, text=True, timeout=300, env=env)
        assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
        with Image.open(work / "janus.png") as im:
            rgb = np.asarray(im.convert("RGB"), dtype=int)
        red = (rgb[..., 0] > 150) & (rgb[..., 2] < 110)
        blue = (rgb[..., 2] > 130) & (rgb[..., 0] < 110)
        assert red.sum() > 500 and blue.sum() > 500, (kind, red.sum(), blue.sum())
        keep = Path(os.environ.get("ROTOMORPH_KEEP", tmp_path))  # to look at the pictures
        shutil.copy(work / "janus.png", keep / f"{kind}.png")
