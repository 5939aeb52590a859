"""ParaView writer: .vtp read back through meshio's independent VTK XML decoder, and .pvd."""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from rotomorph.errors import InvalidParameterError
from rotomorph.io.vtk import network_lines, write_pvd, write_vtp, write_vtp_series


def read_vtp_with_meshio(path, tmp_path):
    """Decode our PolyData with meshio (which reads UnstructuredGrid XML only).

    The Points, PointData and the Lines/CellData arrays are moved verbatim (encoded bytes and
    attributes unchanged) into a .vtu: points/point data as such, line arrays as FieldData, with
    one vertex cell per point so that the grid is valid. Returns points, lines, point data,
    cell data as meshio decoded them.
    """
    root = ET.parse(path).getroot()
    assert root.get("type") == "PolyData"
    piece = root.find("PolyData/Piece")
    n_points = int(piece.get("NumberOfPoints"))
    n_lines = int(piece.get("NumberOfLines"))
    root.set("type", "UnstructuredGrid")
    grid = root.find("PolyData")
    grid.tag = "UnstructuredGrid"
    field = ET.Element("FieldData")
    for array in piece.find("Lines"):
        field.append(array)
    for array in piece.find("CellData"):
        array.set("Name", "cell:" + array.get("Name"))
        field.append(array)
    grid.insert(0, field)
    for tag in ("Lines", "CellData"):
        piece.remove(piece.find(tag))
    for key in ("NumberOfVerts", "NumberOfLines", "NumberOfStrips", "NumberOfPolys"):
        del piece.attrib[key]
    piece.set("NumberOfCells", str(n_points))
    cells = ET.SubElement(piece, "Cells")
    for name, values, vtype in (
        ("connectivity", range(n_points), "Int64"),
        ("offsets", range(1, n_points + 1), "Int64"),
        ("types", [1] * n_points, "UInt8"),
    ):
        arr = ET.SubElement(cells, "DataArray", type=vtype, Name=name, format="ascii")
        arr.text = " ".join(map(str, values))
    out = tmp_path / "converted.vtu"
    ET.ElementTree(root).write(out, encoding="UTF-8", xml_declaration=True)
    mesh = meshio.read(out)
    conn = np.asarray(mesh.field_data["connectivity"]).astype(int).ravel()
    offsets = np.asarray(mesh.field_data["offsets"]).astype(int).ravel()
    assert len(offsets) == n_lines
    lines = np.split(conn, offsets[:-1]) if n_lines else []
    cell_data = {k[5:]: v for k, v in mesh.field_data.items() if k.startswith("cell:")}
    return mesh.points, lines, mesh.point_data, cell_data


@pytest.fixture
def polylines():
    rng = np.random.default_rng(0)
    points = rng.normal(size=(9, 3)) * 10.0
    lines = [np.array([0, 1, 2, 3]), np.array([3, 4, 5]), np.array([5, 6, 7, 8, 0])]
    data = {
        "dkappa_over_kappa": rng.normal(size=9),
        "twist": np.r_[rng.normal(size=8), np.nan],
        "alpha": rng.normal(size=(9, 3)),
        "s": np.arange(9),
        "branch": np.arange(9) % 3 == 0,
    }
    return points, lines, data


@pytest.mark.parametrize("binary", [True, False])
def test_vtp_round_trip_through_meshio(tmp_path, polylines, binary):
    points, lines, data = polylines
    if not binary:
        data = {k: v for k, v in data.items() if k != "twist"}  # ASCII: no NaN for ParaView
    path = write_vtp(
        tmp_path / "net.vtp",
        points,
        lines,
        point_data=data,
        cell_data={"edge_ratio": [1.0, 1.5, 0.5]},
        binary=binary,
    )
    pts, got_lines, pdata, cdata = read_vtp_with_meshio(path, tmp_path)
    np.testing.assert_array_equal(pts, points)
    assert [g.tolist() for g in got_lines] == [line.tolist() for line in lines]
    assert set(pdata) == set(data)
    for name, value in data.items():
        np.testing.assert_array_equal(np.asarray(pdata[name]).reshape(np.shape(value)), value)
    np.testing.assert_array_equal(np.ravel(cdata["edge_ratio"]), [1.0, 1.5, 0.5])


def test_vtp_header_and_unicode_names(tmp_path, polylines):
    points, lines, _ = polylines
    path = write_vtp(tmp_path / "u.vtp", points, lines, point_data={"Δκ/κ": np.ones(9)})
    root = ET.parse(path).getroot()
    assert root.get("header_type") == "UInt64" and root.get("byte_order") == "LittleEndian"
    piece = root.find("PolyData/Piece")
    assert piece.get("NumberOfPoints") == "9" and piece.get("NumberOfLines") == "3"
    assert piece.find("PointData/DataArray").get("Name") == "Δκ/κ"
    assert os.listdir(tmp_path) == ["u.vtp"]


def test_vtp_rejects_bad_input(tmp_path, polylines):
    points, lines, _ = polylines
    with pytest.raises(InvalidParameterError, match=r"lines\[1\]"):
        write_vtp(tmp_path / "x.vtp", points, [lines[0], np.array([3, 99])])
    with pytest.raises(InvalidParameterError, match="point_data"):
        write_vtp(tmp_path / "x.vtp", points, lines, point_data={"a": np.ones(8)})
    with pytest.raises(InvalidParameterError, match="points"):
        write_vtp(tmp_path / "x.vtp", points[:, :2], lines)
    assert os.listdir(tmp_path) == []


def test_network_lines():
    chain = np.array([[0, 1], [1, 2], [2, 3]])
    assert [x.tolist() for x in network_lines(chain)] == [[0, 1, 2, 3]]
    # a T junction: three lines meeting at node 2
    tee = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [2, 5]])
    lines = sorted(sorted(x.tolist()) for x in network_lines(tee))
    assert lines == [[0, 1, 2], [2, 3, 4], [2, 5]]
    # a branch flag splits a chain; a ring is closed
    assert len(network_lines(chain, branch=np.array([0, 1, 0, 0], bool))) == 2
    ring = np.array([[0, 1], [1, 2], [2, 0]])
    (loop,) = network_lines(ring)
    assert loop[0] == loop[-1] and len(loop) == 4
    assert network_lines(np.zeros((0, 2), int)) == []


def test_series_and_pvd(tmp_path, polylines):
    points, lines, _ = polylines
    frames = np.stack([points * (1 + 0.1 * s) for s in range(3)])
    pvd = write_vtp_series(
        tmp_path / "morph.pvd",
        frames,
        lines,
        times=[0.0, 0.5, 1.0],
        point_data={"s": np.tile(np.arange(9.0), (3, 1))},
    )
    assert sorted(os.listdir(tmp_path)) == [
        "morph.pvd",
        "morph_0000.vtp",
        "morph_0001.vtp",
        "morph_0002.vtp",
    ]
    root = ET.parse(pvd).getroot()
    assert root.get("type") == "Collection"
    sets = root.findall("Collection/DataSet")
    assert [float(d.get("timestep")) for d in sets] == [0.0, 0.5, 1.0]
    assert [d.get("file") for d in sets] == ["morph_0000.vtp", "morph_0001.vtp", "morph_0002.vtp"]
    pts, _, _, _ = read_vtp_with_meshio(tmp_path / sets[2].get("file"), tmp_path)
    np.testing.assert_allclose(pts, points * 1.2)


def test_pvd_relative_paths(tmp_path):
    (tmp_path / "frames").mkdir()
    pvd = write_pvd(tmp_path / "a.pvd", [(0.0, tmp_path / "frames" / "f0.vtp")])
    assert 'file="frames/f0.vtp"' in pvd.read_text()
    with pytest.raises(InvalidParameterError, match="finite"):
        write_pvd(tmp_path / "b.pvd", [(np.nan, "x.vtp")])


@pytest.mark.parametrize("binary", [True, False])
def test_vtu_line_cells_read_by_meshio(tmp_path, binary):
    from rotomorph.io.vtk import write_vtu, write_vtu_series

    rng = np.random.default_rng(1)
    points = rng.normal(size=(6, 3))
    segments = np.array([[0, 1], [1, 2], [2, 3], [3, 4], [4, 5], [5, 0]])
    normals = rng.normal(size=(6, 3))
    path = write_vtu(
        tmp_path / "s.vtu",
        points,
        segments,
        point_data={"twist [1/mm]": np.r_[np.nan, rng.normal(size=5)]},
        cell_data={"active_normal": normals, "lattice_edge": np.arange(6)},
        binary=binary,
    )
    mesh = meshio.read(path)
    np.testing.assert_allclose(mesh.points, points)
    np.testing.assert_array_equal(mesh.cells_dict["line"], segments)
    np.testing.assert_allclose(mesh.cell_data["active_normal"][0], normals)
    np.testing.assert_array_equal(mesh.cell_data["lattice_edge"][0].ravel(), np.arange(6))
    assert np.isnan(mesh.point_data["twist [1/mm]"][0])
    frames = np.stack([points, points + 1.0])
    pvd = write_vtu_series(
        tmp_path / "seg.pvd",
        frames,
        segments,
        times=[25.0, 175.0],
        cell_data={"radius [mm]": np.full((2, 6), 0.3)},
    )
    assert pvd.read_text().count("<DataSet") == 2
    np.testing.assert_allclose(meshio.read(tmp_path / "seg_0001.vtu").points, points + 1.0)
    with pytest.raises(InvalidParameterError, match="segments"):
        write_vtu(tmp_path / "bad.vtu", points, [[0, 6]])
    with pytest.raises(InvalidParameterError, match="cell_data"):
        write_vtu(tmp_path / "bad.vtu", points, segments, cell_data={"x": np.zeros(5)})
    assert not (tmp_path / "bad.vtu").exists()
