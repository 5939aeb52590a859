"""A small writer of VTK XML files for ParaView: ``.vtp`` polylines and surfaces, ``.vtu``
line cells and ``.pvd`` time series.

``.vtp`` (PolyData) holds points (mm), polylines (one per lattice edge chain or network
segment) and/or polygons (e.g. the facets of a tube surface), and point/cell data arrays (e.g.
``"curvature [1/mm]"``, ``"twist [1/mm]"``, ``"s [mm]"``). Data arrays are written either
inline-base64 ``binary`` (VTK's "binary" format: a ``UInt64`` byte count and the data, each
base64-encoded, little-endian), zlib-``compress``-ed binary (VTK's ``vtkZLibDataCompressor``
layout: a ``UInt64`` block header — block count, block size, last block size, compressed sizes
— and the compressed blocks, each base64-encoded), or ``ascii``. ParaView's ASCII parser does
not accept ``nan``; write binary when arrays may hold NaN (the default).

``.vtu`` (UnstructuredGrid) holds the same points with one line cell per network segment, so
per-segment arrays (material directors, the interface normal toward the active half, radius)
are cell data; unlike ``.vtp`` it is read by meshio as well as by ParaView and PyVista.

``.pvd`` (Collection) lists one ``.vtp`` (or ``.vtu``) per time step with its ``timestep``
value, so ParaView plays the morphing as an animation. All files are written atomically.
"""

from __future__ import annotations

import base64
import os
import zlib
from collections.abc import Mapping, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

import numpy as np

from rotomorph._typing import BoolArray, FloatArray, IntArray
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_write_text

__all__ = [
    "network_lines",
    "write_pvd",
    "write_vtp",
    "write_vtp_series",
    "write_vtu",
    "write_vtu_series",
]

_VTK_TYPES = {
    np.dtype(np.float64): "Float64",
    np.dtype(np.float32): "Float32",
    np.dtype(np.int64): "Int64",
    np.dtype(np.int32): "Int32",
    np.dtype(np.uint8): "UInt8",
    np.dtype(np.int8): "Int8",
}


def network_lines(edges: IntArray, branch: BoolArray | None = None) -> list[IntArray]:
    """Split a network into maximal polylines that pass only through ordinary nodes.

    Parameters
    ----------
    edges
        ``(E, 2)`` segment end-node indices.
    branch
        ``(N,)`` branch flags; polylines also stop at these (besides nodes of degree != 2).

    Returns
    -------
    list of ndarray
        Node-index arrays covering every segment exactly once; a closed loop of ordinary nodes
        is returned with its first node repeated at the end. Empty for no edges.
    """
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0:
        return []
    n = int(e.max()) + 1 if branch is None else len(branch)
    incident: list[list[int]] = [[] for _ in range(n)]
    for j, (a, b) in enumerate(e):
        incident[a].append(j)
        incident[b].append(j)
    stop = np.array([len(x) != 2 for x in incident])
    if branch is not None:
        stop |= np.asarray(branch, dtype=bool)
    used = np.zeros(len(e), dtype=bool)

    def walk(start: int, first: int) -> IntArray:
        nodes, node, edge = [start], start, first
        while True:
            used[edge] = True
            a, b = e[edge]
            node = int(b if a == node else a)
            nodes.append(node)
            if stop[node] or node == start:
                return np.array(nodes, dtype=np.int64)
            edge = next(k for k in incident[node] if not used[k])

    lines = []
    for node in np.flatnonzero(stop):
        for edge in incident[node]:
            if not used[edge]:
                lines.append(walk(int(node), edge))
    for edge in range(len(e)):
        if not used[edge]:
            lines.append(walk(int(e[edge, 0]), edge))
    return lines


#: Uncompressed bytes per zlib block of a compressed data array (VTK's default is 32 KiB).
_BLOCK = 1 << 16


def _encode(values: np.ndarray, binary: bool, compress: bool = False) -> str:
    if binary:
        data = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder("<")).tobytes()
        if compress:
            blocks = [data[i : i + _BLOCK] for i in range(0, len(data), _BLOCK)] or [b""]
            packed = [zlib.compress(b, 6) for b in blocks]
            sizes = [len(blocks), _BLOCK, len(blocks[-1]), *map(len, packed)]
            header = np.array(sizes, dtype="<u8").tobytes()
            return (base64.b64encode(header) + base64.b64encode(b"".join(packed))).decode("ascii")
        header = np.array([len(data)], dtype="<u8").tobytes()
        return (base64.b64encode(header) + base64.b64encode(data)).decode("ascii")
    if values.dtype.kind == "f":
        return " ".join(f"{v:.17g}" for v in values.ravel())
    return " ".join(str(int(v)) for v in values.ravel())


def _data_array(
    name: str, values: np.ndarray, binary: bool, indent: str, compress: bool = False
) -> str:
    comps = 1 if values.ndim == 1 else int(np.prod(values.shape[1:]))
    fmt = "binary" if binary else "ascii"
    return (
        f'{indent}<DataArray type="{_VTK_TYPES[values.dtype]}" Name={quoteattr(name)} '
        f'NumberOfComponents="{comps}" format="{fmt}">\n'
        f"{indent}  {_encode(values, binary, compress and binary)}\n{indent}</DataArray>\n"
    )


def _file_header(kind: str, compress: bool) -> str:
    zlib_attr = ' compressor="vtkZLibDataCompressor"' if compress else ""
    return (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        f'<VTKFile type="{kind}" version="1.0" byte_order="LittleEndian" '
        f'header_type="UInt64"{zlib_attr}>\n'
    )


def _attributes(tag: str, arrays: Mapping[str, np.ndarray], active: Mapping[str, str]) -> str:
    """``<PointData Normals="...">``: the arrays ParaView takes as normals/scalars."""
    attrs = "".join(f" {k}={quoteattr(v)}" for k, v in active.items() if v in arrays)
    return f"      <{tag}{attrs}>\n"


def _as_data(name: str, value: object, count: int, what: str) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype == bool:
        a = a.astype(np.uint8)
    elif a.dtype in (np.int8, np.uint8, np.float32):
        pass  # kept as given: flags and single precision stay small
    elif a.dtype.kind in "iu":
        a = a.astype(np.int64)
    else:
        a = a.astype(np.float64)
    if a.ndim not in (1, 2) or a.shape[0] != count:
        raise InvalidParameterError(
            f"{what}[{name!r}]", f"must have shape ({count},) or ({count}, k); got {a.shape}"
        )
    return a


def _cells(
    items: Sequence[IntArray] | IntArray, n: int, what: str, least: int
) -> tuple[np.ndarray, np.ndarray]:
    """Checked VTK ``connectivity`` and ``offsets`` of cells given as index arrays (or as one
    ``(C, k)`` array of cells of k nodes each)."""
    if isinstance(items, np.ndarray) and items.ndim == 2:
        idx = items.astype(np.int64)
        if idx.size and (idx.shape[1] < least or idx.min() < 0 or idx.max() >= n):
            raise InvalidParameterError(
                what, f"needs >= {least} node indices per cell in [0, {n - 1}]; got {idx.shape}"
            )
        return idx.reshape(-1), np.arange(1, len(idx) + 1, dtype=np.int64) * idx.shape[1]
    parts = []
    for k, item in enumerate(items):
        one = np.asarray(item, dtype=np.int64).reshape(-1)
        if len(one) < least or one.min() < 0 or one.max() >= n:
            raise InvalidParameterError(
                f"{what}[{k}]", f"needs >= {least} node indices in [0, {n - 1}]; got {one.tolist()}"
            )
        parts.append(one)
    connectivity = np.concatenate(parts) if parts else np.zeros(0, np.int64)
    return connectivity, np.cumsum([len(c) for c in parts], dtype=np.int64)


def _cell_block(tag: str, cells: tuple[np.ndarray, np.ndarray], binary: bool, z: bool) -> str:
    return (
        f"      <{tag}>\n"
        + _data_array("connectivity", cells[0], binary, "        ", z)
        + _data_array("offsets", cells[1], binary, "        ", z)
        + f"      </{tag}>\n"
    )


def write_vtp(
    path: str | os.PathLike[str],
    points: FloatArray,
    lines: Sequence[IntArray],
    *,
    polys: Sequence[IntArray] | IntArray = (),
    point_data: Mapping[str, object] | None = None,
    cell_data: Mapping[str, object] | None = None,
    normals: str | None = None,
    binary: bool = True,
    compress: bool = False,
) -> Path:
    """Write polylines and polygons with data arrays as a VTK XML PolyData file (``.vtp``).

    Parameters
    ----------
    path
        Destination file; its folder must exist.
    points
        ``(N, 3)`` point coordinates (mm); single precision is kept as such.
    lines
        Node-index arrays, one polyline each (at least two nodes), e.g. the lattice's
        edge chains or :func:`network_lines`.
    polys
        Node-index arrays, one polygon each (at least three nodes, counter-clockwise seen
        from outside), e.g. ``(F, 4)`` quadrilateral facets of a surface.
    point_data
        Arrays ``(N,)`` or ``(N, k)`` by name (float, int or bool; ``float32``, ``int8`` and
        ``uint8`` are kept, other floats and ints written as 64-bit).
    cell_data
        Arrays ``(L + P,)`` or ``(L + P, k)`` by name, one value per cell: the ``L`` lines
        first, then the ``P`` polygons (VTK's order).
    normals
        Name of a ``(N, 3)`` point array ParaView should shade with (smooth surfaces).
    binary
        Inline base64 (default) or ASCII data arrays.
    compress
        zlib-compress binary arrays (``vtkZLibDataCompressor``; much smaller for repetitive
        data such as surface connectivity).

    Raises
    ------
    InvalidParameterError
        Shapes that do not match, non-finite coordinates, or a cell with an invalid index.
    """
    pts = np.asarray(points)
    pts = pts if pts.dtype == np.float32 else pts.astype(np.float64)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InvalidParameterError("points", f"must have shape (N, 3) in mm; got {pts.shape}")
    if not np.isfinite(pts).all():
        raise InvalidParameterError("points", "must be finite")
    n = len(pts)
    line_cells = _cells(lines, n, "lines", 2)
    poly_cells = _cells(polys, n, "polys", 3)
    n_lines, n_polys = len(line_cells[1]), len(poly_cells[1])
    cells = n_lines + n_polys
    pd = {k: _as_data(k, v, n, "point_data") for k, v in (point_data or {}).items()}
    cd = {k: _as_data(k, v, cells, "cell_data") for k, v in (cell_data or {}).items()}
    if normals is not None and (normals not in pd or pd[normals].shape != (n, 3)):
        raise InvalidParameterError("normals", f"must name an (N, 3) point array; got {normals!r}")
    z = compress and binary
    out = [
        _file_header("PolyData", z),
        "  <PolyData>\n",
        f'    <Piece NumberOfPoints="{n}" NumberOfVerts="0" NumberOfLines="{n_lines}" '
        f'NumberOfStrips="0" NumberOfPolys="{n_polys}">\n',
    ]
    for tag, arrays, active in (
        ("PointData", pd, {"Normals": normals or ""}),
        ("CellData", cd, {}),
    ):
        out.append(_attributes(tag, arrays, active))
        out += [_data_array(k, v, binary, "        ", z) for k, v in arrays.items()]
        out.append(f"      </{tag}>\n")
    out.append("      <Points>\n")
    out.append(_data_array("Points", pts, binary, "        ", z))
    out.append("      </Points>\n")
    if n_lines or not n_polys:
        out.append(_cell_block("Lines", line_cells, binary, z))
    if n_polys:
        out.append(_cell_block("Polys", poly_cells, binary, z))
    out.append("    </Piece>\n  </PolyData>\n</VTKFile>\n")
    return atomic_write_text(path, "".join(out))


def write_pvd(
    path: str | os.PathLike[str], datasets: Sequence[tuple[float, str | os.PathLike[str]]]
) -> Path:
    """Write a ParaView collection (``.pvd``) listing ``(time, file)`` pairs.

    Parameters
    ----------
    path
        Destination ``.pvd``; its folder must exist.
    datasets
        ``(timestep, file)`` pairs; the time is any monotone parameter (e.g. actuation x, or
        temperature in °C). Files are stored relative to the ``.pvd``'s folder.
    """
    folder = Path(path).parent
    rows = []
    for t, file in datasets:
        if not np.isfinite(t):
            raise InvalidParameterError("datasets", f"timestep must be finite; got {t}")
        rel = Path(os.path.relpath(Path(file), folder)) if Path(file).is_absolute() else file
        name = Path(rel).as_posix()
        rows.append(
            f'    <DataSet timestep="{float(t):.17g}" group="" part="0" file={quoteattr(name)}/>\n'
        )
    text = (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">\n'
        "  <Collection>\n" + "".join(rows) + "  </Collection>\n</VTKFile>\n"
    )
    return atomic_write_text(path, text)


def write_vtp_series(
    path: str | os.PathLike[str],
    frames: FloatArray,
    lines: Sequence[IntArray],
    *,
    times: Sequence[float] | None = None,
    point_data: Mapping[str, object] | None = None,
    binary: bool = True,
    compress: bool = False,
) -> Path:
    """Write one ``.vtp`` per step next to a ``.pvd`` that plays them in order.

    Parameters
    ----------
    path
        The ``.pvd`` to write; frames go to ``<stem>_0000.vtp``, ``<stem>_0001.vtp`` … beside it.
    frames
        ``(S, N, 3)`` positions per step (mm).
    lines
        Polylines shared by every frame (see :func:`write_vtp`).
    times
        ``(S,)`` time values (default ``0, 1, …``).
    point_data
        Arrays ``(S, N)`` or ``(S, N, k)`` by name.
    binary, compress
        See :func:`write_vtp`.

    Returns
    -------
    pathlib.Path
        The ``.pvd`` path.
    """
    pos, t, (data,) = _series(frames, times, point_data=point_data)
    target = Path(path)
    entries = []
    for s in range(len(pos)):
        name = f"{target.stem}_{s:04d}.vtp"
        write_vtp(
            target.parent / name,
            pos[s],
            lines,
            point_data={k: v[s] for k, v in data.items()},
            binary=binary,
            compress=compress,
        )
        entries.append((float(t[s]), name))
    return write_pvd(target, entries)


def _series(
    frames: FloatArray, times: Sequence[float] | None, **arrays: Mapping[str, object] | None
) -> tuple[FloatArray, FloatArray, list[dict[str, np.ndarray]]]:
    """Checked positions ``(S, N, 3)``, times ``(S,)`` and per-step data arrays by kind."""
    pos = np.asarray(frames, dtype=float)
    if pos.ndim != 3 or pos.shape[2] != 3:
        raise InvalidParameterError("frames", f"must have shape (S, N, 3) in mm; got {pos.shape}")
    steps = len(pos)
    t = np.arange(steps, dtype=float) if times is None else np.asarray(times, dtype=float)
    if t.shape != (steps,):
        raise InvalidParameterError("times", f"must have one value per frame ({steps})")
    out = []
    for what, given in arrays.items():
        data = {k: np.asarray(v) for k, v in (given or {}).items()}
        for k, v in data.items():
            if v.shape[:1] != (steps,):
                raise InvalidParameterError(f"{what}[{k!r}]", f"needs a leading axis of {steps}")
        out.append(data)
    return pos, t, out


def write_vtu(
    path: str | os.PathLike[str],
    points: FloatArray,
    segments: IntArray,
    *,
    point_data: Mapping[str, object] | None = None,
    cell_data: Mapping[str, object] | None = None,
    binary: bool = True,
    compress: bool = False,
) -> Path:
    """Write segments as VTK XML UnstructuredGrid line cells (``.vtu``), one cell per segment.

    The format meshio, ParaView, VisIt and PyVista all read; per-segment arrays (directors,
    the active side, radius) are cell data.

    Parameters
    ----------
    path
        Destination file; its folder must exist.
    points
        ``(N, 3)`` point coordinates (mm).
    segments
        ``(E, 2)`` node indices of the line cells.
    point_data
        Arrays ``(N,)`` or ``(N, k)`` by name.
    cell_data
        Arrays ``(E,)`` or ``(E, k)`` by name.
    binary
        Inline base64 (default) or ASCII data arrays.
    compress
        zlib-compress binary arrays (see :func:`write_vtp`).

    Raises
    ------
    InvalidParameterError
        Shapes that do not match, non-finite coordinates, or an invalid index.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InvalidParameterError("points", f"must have shape (N, 3) in mm; got {pts.shape}")
    if not np.isfinite(pts).all():
        raise InvalidParameterError("points", "must be finite")
    n = len(pts)
    seg = np.asarray(segments, dtype=np.int64).reshape(-1, 2)
    if len(seg) and (seg.min() < 0 or seg.max() >= n):
        raise InvalidParameterError("segments", f"indices must lie in [0, {n - 1}]")
    pd = {k: _as_data(k, v, n, "point_data") for k, v in (point_data or {}).items()}
    cd = {k: _as_data(k, v, len(seg), "cell_data") for k, v in (cell_data or {}).items()}
    z = compress and binary
    out = [
        _file_header("UnstructuredGrid", z),
        "  <UnstructuredGrid>\n",
        f'    <Piece NumberOfPoints="{n}" NumberOfCells="{len(seg)}">\n',
    ]
    for tag, arrays in (("PointData", pd), ("CellData", cd)):
        out.append(f"      <{tag}>\n")
        out += [_data_array(k, v, binary, "        ", z) for k, v in arrays.items()]
        out.append(f"      </{tag}>\n")
    out.append("      <Points>\n")
    out.append(_data_array("Points", pts, binary, "        ", z))
    out.append("      </Points>\n      <Cells>\n")
    out.append(_data_array("connectivity", seg.reshape(-1), binary, "        ", z))
    offsets = np.arange(2, 2 * len(seg) + 1, 2, dtype=np.int64)
    out.append(_data_array("offsets", offsets, binary, "        ", z))
    types = np.full(len(seg), 3, dtype=np.uint8)  # VTK_LINE
    out.append(_data_array("types", types, binary, "        ", z))
    out.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    return atomic_write_text(path, "".join(out))


def write_vtu_series(
    path: str | os.PathLike[str],
    frames: FloatArray,
    segments: IntArray,
    *,
    times: Sequence[float] | None = None,
    point_data: Mapping[str, object] | None = None,
    cell_data: Mapping[str, object] | None = None,
    binary: bool = True,
    compress: bool = False,
) -> Path:
    """Write one ``.vtu`` per step (:func:`write_vtu`) next to a ``.pvd`` that plays them.

    Parameters are those of :func:`write_vtp_series`; ``cell_data`` arrays are ``(S, E)`` or
    ``(S, E, k)``. Returns the ``.pvd`` path.
    """
    pos, t, (pdata, cdata) = _series(frames, times, point_data=point_data, cell_data=cell_data)
    target = Path(path)
    entries = []
    for s in range(len(pos)):
        name = f"{target.stem}_{s:04d}.vtu"
        write_vtu(
            target.parent / name,
            pos[s],
            segments,
            point_data={k: v[s] for k, v in pdata.items()},
            cell_data={k: v[s] for k, v in cdata.items()},
            binary=binary,
            compress=compress,
        )
        entries.append((float(t[s]), name))
    return write_pvd(target, entries)
