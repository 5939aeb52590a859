"""A small writer of VTK XML files for ParaView: ``.vtp`` polylines and ``.pvd`` time series.

``.vtp`` (PolyData) holds points (mm), one polyline per lattice edge chain or network segment,
and point/cell data arrays (e.g. ``"dkappa_over_kappa"``, ``"twist"``, ``"alpha"``, ``"s"``).
Data arrays are written either inline-base64 ``binary`` (VTK's "binary" format: a ``UInt64``
byte count and the data, each base64-encoded, little-endian) or ``ascii``. ParaView's ASCII
parser does not accept ``nan``; write binary when arrays may hold NaN (the default).

``.vtu`` (UnstructuredGrid) holds the same points with one line cell per network segment, so
per-segment arrays (material directors, the interface normal toward the active half, radius)
are cell data; unlike ``.vtp`` it is read by meshio as well as by ParaView and PyVista.

``.pvd`` (Collection) lists one ``.vtp`` (or ``.vtu``) per time step with its ``timestep``
value, so ParaView plays the morphing as an animation. All files are written atomically.
"""

from __future__ import annotations

import base64
import os
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


def _encode(values: np.ndarray, binary: bool) -> str:
    if binary:
        data = np.ascontiguousarray(values, dtype=values.dtype.newbyteorder("<")).tobytes()
        header = np.array([len(data)], dtype="<u8").tobytes()
        return (base64.b64encode(header) + base64.b64encode(data)).decode("ascii")
    if values.dtype.kind == "f":
        return " ".join(f"{v:.17g}" for v in values.ravel())
    return " ".join(str(int(v)) for v in values.ravel())


def _data_array(name: str, values: np.ndarray, binary: bool, indent: str) -> str:
    comps = 1 if values.ndim == 1 else int(np.prod(values.shape[1:]))
    fmt = "binary" if binary else "ascii"
    return (
        f'{indent}<DataArray type="{_VTK_TYPES[values.dtype]}" Name={quoteattr(name)} '
        f'NumberOfComponents="{comps}" format="{fmt}">\n'
        f"{indent}  {_encode(values, binary)}\n{indent}</DataArray>\n"
    )


def _as_data(name: str, value: object, count: int, what: str) -> np.ndarray:
    a = np.asarray(value)
    if a.dtype == bool:
        a = a.astype(np.uint8)
    elif a.dtype.kind in "iu":
        a = a.astype(np.int64)
    else:
        a = a.astype(np.float64)
    if a.ndim not in (1, 2) or a.shape[0] != count:
        raise InvalidParameterError(
            f"{what}[{name!r}]", f"must have shape ({count},) or ({count}, k); got {a.shape}"
        )
    return a


def write_vtp(
    path: str | os.PathLike[str],
    points: FloatArray,
    lines: Sequence[IntArray],
    *,
    point_data: Mapping[str, object] | None = None,
    cell_data: Mapping[str, object] | None = None,
    binary: bool = True,
) -> Path:
    """Write polylines with data arrays as a VTK XML PolyData file (``.vtp``).

    Parameters
    ----------
    path
        Destination file; its folder must exist.
    points
        ``(N, 3)`` point coordinates (mm).
    lines
        Node-index arrays, one polyline each (at least two nodes), e.g. the lattice's
        edge chains or :func:`network_lines`.
    point_data
        Arrays ``(N,)`` or ``(N, k)`` by name (float, int or bool).
    cell_data
        Arrays ``(L,)`` or ``(L, k)`` by name, one value per polyline.
    binary
        Inline base64 (default) or ASCII data arrays.

    Raises
    ------
    InvalidParameterError
        Shapes that do not match, non-finite coordinates, or a line with an invalid index.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise InvalidParameterError("points", f"must have shape (N, 3) in mm; got {pts.shape}")
    if not np.isfinite(pts).all():
        raise InvalidParameterError("points", "must be finite")
    n = len(pts)
    conn_parts = []
    for k, line in enumerate(lines):
        idx = np.asarray(line, dtype=np.int64).reshape(-1)
        if len(idx) < 2 or idx.min() < 0 or idx.max() >= n:
            raise InvalidParameterError(
                f"lines[{k}]", f"needs >= 2 node indices in [0, {n - 1}]; got {idx.tolist()}"
            )
        conn_parts.append(idx)
    connectivity = np.concatenate(conn_parts) if conn_parts else np.zeros(0, np.int64)
    offsets = np.cumsum([len(c) for c in conn_parts], dtype=np.int64)
    pd = {k: _as_data(k, v, n, "point_data") for k, v in (point_data or {}).items()}
    cd = {k: _as_data(k, v, len(conn_parts), "cell_data") for k, v in (cell_data or {}).items()}
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>\n',
        '<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">\n',
        "  <PolyData>\n",
        f'    <Piece NumberOfPoints="{n}" NumberOfVerts="0" NumberOfLines="{len(conn_parts)}" '
        'NumberOfStrips="0" NumberOfPolys="0">\n',
    ]
    for tag, arrays in (("PointData", pd), ("CellData", cd)):
        out.append(f"      <{tag}>\n")
        out += [_data_array(k, v, binary, "        ") for k, v in arrays.items()]
        out.append(f"      </{tag}>\n")
    out.append("      <Points>\n")
    out.append(_data_array("Points", pts, binary, "        "))
    out.append("      </Points>\n      <Lines>\n")
    out.append(_data_array("connectivity", connectivity, binary, "        "))
    out.append(_data_array("offsets", offsets, binary, "        "))
    out.append("      </Lines>\n    </Piece>\n  </PolyData>\n</VTKFile>\n")
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
    binary
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
    out = [
        '<?xml version="1.0" encoding="UTF-8"?>\n',
        '<VTKFile type="UnstructuredGrid" version="1.0" byte_order="LittleEndian" '
        'header_type="UInt64">\n',
        "  <UnstructuredGrid>\n",
        f'    <Piece NumberOfPoints="{n}" NumberOfCells="{len(seg)}">\n',
    ]
    for tag, arrays in (("PointData", pd), ("CellData", cd)):
        out.append(f"      <{tag}>\n")
        out += [_data_array(k, v, binary, "        ") for k, v in arrays.items()]
        out.append(f"      </{tag}>\n")
    out.append("      <Points>\n")
    out.append(_data_array("Points", pts, binary, "        "))
    out.append("      </Points>\n      <Cells>\n")
    out.append(_data_array("connectivity", seg.reshape(-1), binary, "        "))
    offsets = np.arange(2, 2 * len(seg) + 1, 2, dtype=np.int64)
    out.append(_data_array("offsets", offsets, binary, "        "))
    types = np.full(len(seg), 3, dtype=np.uint8)  # VTK_LINE
    out.append(_data_array("types", types, binary, "        "))
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
        )
        entries.append((float(t[s]), name))
    return write_pvd(target, entries)
