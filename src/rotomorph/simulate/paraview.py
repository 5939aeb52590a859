"""A run as ParaView files: centre lines, segments, Janus tube surfaces and a script to show them.

:func:`write_vtk` writes, into one folder, a time series per representation (each a ``.pvd``
that plays the heating ramp, its ``timestep`` the temperature in °C, or the actuation parameter)
and ``show_janus.py``, a ParaView Python script that opens the tubes with the two halves
coloured by ``active``::

    morphing.pvd + morphing_0000.vtp …   centre lines (polylines), point data
    segments.pvd + segments_0000.vtu …   one line cell per segment, point and cell data (meshio)
    janus.pvd    + janus_0000.vtp …      the Janus tube surface: quadrilateral facets with the
                                         cell flag ``active`` (1 on the LCE half, 0 on the
                                         passive half) and every array of the other two files
    show_janus.py                        ``pvpython show_janus.py`` (or File ▸ Load State)

Every run kind writes the same arrays under the same names, with their unit in brackets
(:data:`POINT_ARRAYS`, :data:`CELL_ARRAYS`): a filament run and a lattice run are coloured by
``curvature [1/mm]`` or ``twist [1/mm]`` alike. Curvature and its relative change are computed
here from the positions, the same way for every run (:func:`centreline_curvature`).

No array holds NaN at a chain end or a junction, where a vertex quantity (curvature, twist)
has no stencil of its own: such a node takes the mean of the values at its neighbouring nodes
(a chain end: its one neighbour; a junction: the first vertex of every incident edge), see
:func:`fill_from_neighbours`. The only NaN left is where a quantity does not exist at all: the
relative curvature change (κ − κ_i)/κ_i of a filament printed straight (κ_i = 0); a run whose
printed shape is straight everywhere does not write that array.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path

import numpy as np

from rotomorph._typing import FloatArray, IntArray
from rotomorph.geometry import curvature_binormal
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.results import RunResults
from rotomorph.io.vtk import (
    network_lines,
    write_pvd,
    write_vtp,
    write_vtp_series,
    write_vtu_series,
)

__all__ = [
    "CELL_ARRAYS",
    "POINT_ARRAYS",
    "SCRIPT",
    "centreline_curvature",
    "fill_from_neighbours",
    "paraview_arrays",
    "write_janus_tubes",
    "write_vtk",
]

#: Per-node arrays of every ParaView file: name in the file ← what it is.
POINT_ARRAYS = {
    "curvature [1/mm]": "discrete curvature |kb|/ℓ_V of the centre line",
    "printed_curvature [1/mm]": "κ_i, the curvature of the printed (initial) centre line",
    "relative_curvature_change [1]": "(κ − κ_i)/κ_i, where the filament was printed curved",
    "twist [1/mm]": "material twist of the director frame",
    "s [mm]": "printed arc length from the start of the filament (lattices: of the edge)",
    "interface_angle [rad]": "printed interface angle α (mean of the node's segments)",
    "radius [mm]": "filament radius (mean of the node's segments)",
    "active_fraction [1]": "active area fraction of the section (mean of the node's segments)",
    "active_normal [1]": "interface normal toward the active half (mean of the node's segments)",
    "directors [1]": "material director m₁ (mean of the node's segments)",
    "filament_id": "filament index (lattices: lattice edge; −1 at junctions)",
}
#: Per-segment arrays (cell data of ``segments`` and ``janus``).
CELL_ARRAYS = {
    "interface_angle [rad]": "printed interface angle α",
    "radius [mm]": "filament radius",
    "active_fraction [1]": "active area fraction of the section",
    "active_normal [1]": "interface normal toward the active half",
    "directors [1]": "material director m₁",
    "end_to_end_ratio [1]": "L/L0 of the segment's filament (lattices: of its lattice edge)",
    "filament_id": "filament index of the segment (lattices: lattice edge)",
}
#: Facets around a segment of the tube surface (even: a half-and-half section splits exactly).
TUBE_FACETS = 12


def centreline_curvature(positions: FloatArray, lines: list[IntArray]) -> FloatArray:
    """Discrete curvature ``|kb|/ℓ_V`` (1/mm) at the interior vertices of ``lines``.

    Parameters
    ----------
    positions
        ``(S, N, 3)`` node positions per step (mm).
    lines
        Polylines through ordinary nodes (:func:`~rotomorph.io.vtk.network_lines`).

    Returns
    -------
    ndarray
        ``(S, N)``; NaN at nodes interior to no line (chain ends, junctions). The rod solver's
        and :func:`~rotomorph.analysis.curvature.discrete_curvature`'s definition.
    """
    pos = np.asarray(positions, dtype=float)
    out = np.full(pos.shape[:2], np.nan)
    triples = [np.stack([c[:-2], c[1:-1], c[2:]], axis=1) for c in lines if len(c) >= 3]
    if not triples:
        return out
    prev, mid, nxt = np.concatenate(triples).T
    e, f = pos[:, mid] - pos[:, prev], pos[:, nxt] - pos[:, mid]
    voronoi = 0.5 * (np.linalg.norm(e, axis=-1) + np.linalg.norm(f, axis=-1))
    out[:, mid] = np.linalg.norm(curvature_binormal(e, f), axis=-1) / voronoi
    return out


def fill_from_neighbours(values: FloatArray, edges: IntArray, *, sweeps: int = 4) -> FloatArray:
    """Per-node ``(S, N, ...)`` values with NaN nodes set to the mean of their finite neighbours.

    A chain end takes its one neighbour's value, a junction the mean over the first vertices of
    its incident edges. Repeated ``sweeps`` times, so a NaN two nodes away from any value is
    filled too; nodes with no finite value within that reach stay NaN.
    """
    out = np.array(values, dtype=float)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    if len(e) == 0:
        return out
    a = np.concatenate([e[:, 0], e[:, 1]])
    b = np.concatenate([e[:, 1], e[:, 0]])
    n = out.shape[1]
    for _ in range(sweeps):
        missing = np.isnan(out).any(axis=tuple(range(2, out.ndim)))
        if not missing.any():
            break
        for k in np.flatnonzero(missing.any(axis=1)):
            src = out[k][b]
            ok = ~np.isnan(src).reshape(len(b), -1).any(axis=1)
            total = np.zeros((n, *out.shape[2:]))
            np.add.at(total, a[ok], src[ok])
            count = np.bincount(a[ok], minlength=n).astype(float)
            fill = missing[k] & (count > 0)
            shape = (-1,) + (1,) * (out.ndim - 2)
            out[k][fill] = total[fill] / count[fill].reshape(shape)
    return out


def _segments_to_nodes(values: np.ndarray, edges: np.ndarray, n: int) -> np.ndarray:
    """Mean over each node's segments of per-segment ``(S, E, ...)`` values → ``(S, N, ...)``;
    3-vectors are renormalised (unit directions stay unit where they do not cancel)."""
    out = np.zeros((values.shape[0], n, *values.shape[2:]))
    count = np.zeros(n)
    clean = np.nan_to_num(values)
    for end in (0, 1):
        for k in range(values.shape[0]):
            np.add.at(out[k], edges[:, end], clean[k])
        np.add.at(count, edges[:, end], 1.0)
    shape = (1, n) + (1,) * (values.ndim - 2)
    out /= np.maximum(count, 1.0).reshape(shape)
    if values.ndim == 3 and values.shape[2] == 3:
        norm = np.linalg.norm(out, axis=2, keepdims=True)
        out = np.where(norm > 1e-9, out / np.where(norm > 0, norm, 1.0), 0.0)
    return out


def _per_step(v: np.ndarray, steps: int) -> np.ndarray:
    return np.broadcast_to(v, (steps, *v.shape))


def _named(name: str, units: Mapping[str, str]) -> str:
    unit = units.get(name, "1")
    return f"{name} [{unit or '1'}]"


def paraview_arrays(results: RunResults) -> tuple[dict[str, np.ndarray], dict[str, np.ndarray]]:
    """Point ``(S, N, ...)`` and cell ``(S, E, ...)`` arrays of a run by their ParaView names.

    The names of :data:`POINT_ARRAYS` and :data:`CELL_ARRAYS` for every run kind, then any other
    stored per-node or per-segment field as ``"name [unit]"``. Node values are free of NaN at
    chain ends and junctions (module docstring).
    """
    pos = results.positions
    steps, n = pos.shape[:2]
    edges = np.asarray(results.edges, dtype=np.int64).reshape(-1, 2)
    e = len(edges)
    lines = network_lines(edges, results.branch)
    static, fields, units = results.static, results.fields, results.units
    point: dict[str, np.ndarray] = {}
    cell: dict[str, np.ndarray] = {}

    kappa = centreline_curvature(pos, lines)
    point["curvature [1/mm]"] = kappa
    kappa_i = kappa[0]
    point["printed_curvature [1/mm]"] = _per_step(kappa_i, steps)
    finite_i = kappa_i[np.isfinite(kappa_i)]
    floor = 1e-9 * float(finite_i.max(initial=0.0))
    curved = np.isfinite(kappa_i) & (kappa_i > floor) & (floor > 0)
    if curved.any():
        rel = np.full_like(kappa, np.nan)
        rel[:, curved] = (kappa[:, curved] - kappa_i[curved]) / kappa_i[curved]
        # ends and junctions only: a vertex printed straight keeps NaN (the ratio does not exist)
        undefined_stencil = ~np.isfinite(kappa_i)
        filled = fill_from_neighbours(rel, edges)
        rel[:, undefined_stencil] = filled[:, undefined_stencil]
        point["relative_curvature_change [1]"] = rel
    if "twist" in fields and fields["twist"].shape[:2] == (steps, n):
        point["twist [1/mm]"] = fields["twist"]
    if "arc_length" in static and len(static["arc_length"]) == n:
        point["s [mm]"] = _per_step(np.asarray(static["arc_length"], dtype=float), steps)

    for name, unit in (("interface_angle", "rad"), ("radius", "mm"), ("active_fraction", "1")):
        v = static.get(name)
        if v is not None and len(v) == e and np.isfinite(np.asarray(v, dtype=float)).any():
            cell[f"{name} [{unit}]"] = _per_step(np.asarray(v, float), steps)
    for name in ("active_normal", "directors"):
        v = fields.get(name)
        if v is not None and v.shape[:2] == (steps, e) and np.isfinite(v).any():
            cell[f"{name} [1]"] = v
    owner = static.get("lattice_edge", static.get("segment_filament_id"))
    ratio = fields.get("edge_end_to_end_ratio", fields.get("end_to_end_ratio_per_filament"))
    if owner is not None and ratio is not None and len(owner) == e and ratio.ndim == 2:
        own = np.asarray(owner, dtype=np.int64)
        if own.max(initial=-1) < ratio.shape[1]:
            cell["end_to_end_ratio [1]"] = np.where(
                own[None, :] >= 0, ratio[:, np.maximum(own, 0)], np.nan
            )
    if "filament_id" in static and len(static["filament_id"]) == n:
        point["filament_id"] = _per_step(np.asarray(static["filament_id"], np.int64), steps)
    if owner is not None and len(owner) == e:
        cell["filament_id"] = _per_step(np.asarray(owner, dtype=np.int64), steps)

    known = {
        "twist", "curvature", "relative_curvature_change", "active_normal", "directors",
        "end_to_end_ratio_per_filament", "edge_end_to_end_ratio", "arc_length", "filament_id",
        "segment_filament_id", "lattice_edge", "interface_angle", "radius", "active_fraction",
    }  # fmt: skip
    for name, v in {**fields, **{k: _per_step(v, steps) for k, v in static.items()}}.items():
        if name in known or v.ndim < 2 or v.dtype.kind not in "fiu":
            continue
        if v.shape[1] == n:
            point.setdefault(_named(name, units), np.asarray(v))
        elif v.shape[1] == e:
            cell.setdefault(_named(name, units), np.asarray(v))
    # per-segment arrays also per node (mean of the node's segments), for the polylines
    for name, v in cell.items():
        if name not in point and v.dtype.kind == "f":
            point[name] = _segments_to_nodes(np.asarray(v, dtype=float), edges, n)
    for name, v in point.items():
        if v.dtype.kind == "f" and name != "relative_curvature_change [1]":
            point[name] = fill_from_neighbours(v, edges)
    return point, cell


def _tube_step(
    positions: FloatArray, edges: IntArray, radius: np.ndarray, normals: np.ndarray | None,
    fraction: np.ndarray,
) -> tuple[FloatArray, FloatArray, np.ndarray]:  # fmt: skip
    """Ring points ``(E·2·k, 3)``, their outward normals and the active flag per facet."""
    from rotomorph.plot.tubes import tube_mesh

    k = TUBE_FACETS
    quads, _, active, _ = tube_mesh(
        positions, edges, radius, normals, facets=k, active_fraction=fraction
    )
    m = len(edges)
    q = quads.reshape(m, k, 4, 3)
    rings = np.stack([q[:, :, 0], q[:, :, 3]], axis=1)  # (E, 2, k, 3): start and end rings
    centres = positions[edges][:, :, None, :]
    radial = rings - centres
    radial /= np.maximum(np.linalg.norm(radial, axis=-1, keepdims=True), 1e-300)
    flag = np.full(m * k, -1, dtype=np.int8) if active is None else active.astype(np.int8)
    return rings.reshape(-1, 3), radial.reshape(-1, 3), flag


def _single(v: np.ndarray) -> np.ndarray:
    """Floats in single precision (what ParaView renders with), other arrays as they are."""
    return v.astype(np.float32) if v.dtype.kind == "f" else v


def write_janus_tubes(
    path: str | os.PathLike[str],
    results: RunResults,
    point: Mapping[str, np.ndarray],
    cell: Mapping[str, np.ndarray],
    times: list[float] | None,
) -> Path:
    """The Janus tube surface per step (``janus_0000.vtp`` …) and its ``.pvd``.

    Each segment is a tube of :data:`TUBE_FACETS` quadrilateral facets between its two end
    rings (mitred where the filament continues, as in the figures), with cell data ``active``
    (``Int8``: 1 on the active half, 0 on the passive half, −1 where the run stored no sides),
    ``segment_id`` and every per-segment array; the ring points carry the per-node arrays of
    their node and their outward unit ``Normals`` (smooth shading). Single precision, zlib
    compressed: the surface is for looking at; the exact values are in ``segments.vtu`` and
    ``results.h5``.
    """
    target = Path(path)
    edges = np.asarray(results.edges, dtype=np.int64).reshape(-1, 2)
    m, k = len(edges), TUBE_FACETS
    radius = np.asarray(results.static.get("radius", np.full(m, 0.3)), dtype=float)
    radius = np.where(np.isfinite(radius) & (radius > 0), radius, 0.3)
    fraction = np.asarray(results.static.get("active_fraction", np.full(m, 0.5)), dtype=float)
    fraction = np.where((fraction >= 0) & (fraction <= 1), fraction, 0.5)
    seg = np.arange(m)
    base = (seg[:, None] * 2) * k
    i = np.arange(k)[None, :]
    j = (i + 1) % k
    quads = np.stack([base + i, base + j, base + k + j, base + k + i], axis=-1).reshape(-1, 4)
    ring_node = np.repeat(edges.reshape(-1), k)  # the node of every ring point
    facet_seg = np.repeat(seg, k)
    normals = results.fields.get("active_normal")
    entries = []
    for step in range(results.n_steps):
        nor = None
        if normals is not None and np.isfinite(normals[step]).all():
            nor = normals[step]
        pts, radial, active = _tube_step(results.positions[step], edges, radius, nor, fraction)
        # node quantities on the rings (smooth colours along the tube); per-segment ones as
        # cell data only (the same names as in segments.vtu)
        pdata = {name: _single(v[step][ring_node]) for name, v in point.items() if name not in cell}
        pdata["Normals"] = radial.astype(np.float32)
        cdata: dict[str, np.ndarray] = {"active": active, "segment_id": facet_seg}
        cdata.update({name: _single(v[step][facet_seg]) for name, v in cell.items()})
        name = f"{target.stem}_{step:04d}.vtp"
        write_vtp(
            target.parent / name,
            pts.astype(np.float32),
            [],
            polys=quads,
            point_data=pdata,
            cell_data=cdata,
            normals="Normals",
            compress=True,
        )
        entries.append((float(step) if times is None else times[step], name))
    return write_pvd(target, entries)


#: ParaView Python script written beside the files (``show_janus.py``).
SCRIPT = '''\
"""Show this run's Janus tubes in ParaView, the active (LCE) half red, the passive half blue.

Run   pvpython show_janus.py                 (an interactive window)
      pvbatch show_janus.py --screenshot     (writes janus.png beside this file, no window)
or, in the ParaView GUI, File > Load State... and choose this file.
Written by rotomorph; the files it opens lie in this folder.
"""

import os
import sys

from paraview.simple import (
    ColorBy, GetActiveViewOrCreate, GetAnimationScene, GetColorTransferFunction, GetScalarBar,
    Interact, PVDReader, Render, ResetCamera, SaveScreenshot, Show,
)

HERE = os.path.dirname(os.path.abspath(__file__)) if "__file__" in globals() else os.getcwd()
ACTIVE, PASSIVE = {active}, {passive}

tubes = PVDReader(registrationName="janus tubes", FileName=os.path.join(HERE, "janus.pvd"))
view = GetActiveViewOrCreate("RenderView")
view.Background = [1.0, 1.0, 1.0]
try:  # ParaView >= 5.10 keeps a separate palette background
    view.UseColorPaletteForBackground = 0
except AttributeError:
    pass
shown = Show(tubes, view)
ColorBy(shown, ("CELLS", "active"))
lut = GetColorTransferFunction("active")
lut.InterpretValuesAsCategories = 1
lut.Annotations = ["0", "passive half", "1", "active half (LCE)"]{unknown_label}
lut.IndexedColors = PASSIVE + ACTIVE{unknown_colour}
shown.SetScalarBarVisibility(view, True)
GetScalarBar(lut, view).Title = "{title}"
scene = GetAnimationScene()
scene.UpdateAnimationUsingDataTimeSteps()
scene.AnimationTime = tubes.TimestepValues[-1] if tubes.TimestepValues else 0.0
view.CameraFocalPoint = [{centre}]
view.CameraPosition = [{eye}]
view.CameraViewUp = [0.0, 0.0, 1.0]
ResetCamera(view)
Render(view)
if "--screenshot" in sys.argv:
    SaveScreenshot(os.path.join(HERE, "janus.png"), view, ImageResolution=[1600, 1000])
elif os.path.basename(sys.argv[0] if sys.argv else "") == "show_janus.py":
    Interact(view)  # run by pvpython: keep the window open
'''


def _script(results: RunResults) -> str:
    from matplotlib.colors import to_rgb

    from rotomorph.plot.tubes import ACTIVE_COLOUR, PASSIVE_COLOUR

    end = results.positions[-1]
    centre = 0.5 * (end.min(axis=0) + end.max(axis=0))
    size = float(np.ptp(end, axis=0).max()) or 1.0
    eye = centre + np.array([0.55, -1.0, 0.85]) * 2.0 * size  # from the front, above
    normals = results.fields.get("active_normal")
    unknown = normals is None or not np.isfinite(normals).all()
    return SCRIPT.format(
        active=[round(c, 3) for c in to_rgb(ACTIVE_COLOUR)],
        passive=[round(c, 3) for c in to_rgb(PASSIVE_COLOUR)],
        centre=", ".join(f"{x:.6g}" for x in centre),
        eye=", ".join(f"{x:.6g}" for x in eye),
        unknown_label=' + ["-1", "sides not stored"]' if unknown else "",
        unknown_colour=" + [0.55, 0.55, 0.55]" if unknown else "",
        title="Janus halves",
    )


def write_vtk(results: RunResults, folder: str | os.PathLike[str]) -> list[Path]:
    """The run's ParaView files into ``folder`` (created if missing; module docstring).

    Returns
    -------
    list of pathlib.Path
        ``morphing.pvd``, ``segments.pvd``, ``janus.pvd`` and ``show_janus.py``.
    """
    target = Path(folder)
    target.mkdir(parents=True, exist_ok=True)
    point, cell = paraview_arrays(results)
    times = results.scalars.get("temperature", results.scalars.get("actuation"))
    t = None if times is None else list(map(float, times))
    edges = np.asarray(results.edges, dtype=np.int64).reshape(-1, 2)
    return [
        write_vtp_series(
            target / "morphing.pvd",
            results.positions,
            network_lines(edges, results.branch),
            times=t,
            point_data=point,
            compress=True,
        ),
        write_vtu_series(
            target / "segments.pvd",
            results.positions,
            edges,
            times=t,
            point_data=point,
            cell_data=cell,
            compress=True,
        ),
        write_janus_tubes(target / "janus.pvd", results, point, cell, t),
        atomic_write_text(target / "show_janus.py", _script(results)),
    ]
