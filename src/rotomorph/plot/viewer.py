"""A self-contained interactive HTML 3-D viewer of a run (plotly; optional extra ``[html]``).

:func:`write_viewer` writes one HTML file (plotly.js embedded, no network needed) with the
filaments as tubes, a slider and a play button over the heating ramp and the printed shape as a
faint line. Tubes are coloured by the Janus sides (interface normal toward the active half,
when the run stores ``active_normal``) or by a stored field (per node or per segment) on one
colour scale for the whole ramp. Each frame's title carries the state's verdict
(:mod:`rotomorph.io.validity`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.results import RunResults
from rotomorph.io.validity import assess, run_verdict
from rotomorph.plot.shapes import scalar_norm
from rotomorph.plot.tubes import ACTIVE_COLOUR, PASSIVE_COLOUR, tube_mesh

__all__ = ["viewer_fields", "viewer_figure", "write_viewer"]

#: Radius (mm) of tubes when the run stores none.
DEFAULT_RADIUS = 0.3


def _plotly() -> Any:
    try:
        import plotly.graph_objects as go
    except ImportError as err:
        raise InvalidParameterError(
            "view", f"the HTML viewer needs plotly: pip install 'rotomorph[html]' ({err})"
        ) from None
    return go


def viewer_fields(results: RunResults) -> list[str]:
    """Names a viewer can colour by: ``"janus"`` (if stored) and per-node/per-segment fields."""
    n, e = results.positions.shape[1], len(results.edges)
    names = ["janus"] if "active_normal" in results.fields else []
    for name, v in results.fields.items():
        if v.ndim == 2 and v.shape[1] in (n, e):
            names.append(name)
    return names


def _segment_field(results: RunResults, name: str) -> np.ndarray:
    v = np.asarray(results.fields[name], dtype=float)
    e = results.edges
    if v.shape[1] == len(e) and v.shape[1] != results.positions.shape[1]:
        return v
    ends = v[:, e]  # (S, E, 2)
    with np.errstate(invalid="ignore"):
        return np.nanmean(np.where(np.isfinite(ends), ends, np.nan), axis=2)


def _radius(results: RunResults) -> np.ndarray | float:
    r = results.static.get("radius")
    if r is not None and len(r) == len(results.edges) and np.all(np.asarray(r) > 0):
        return np.asarray(r, dtype=float)
    return DEFAULT_RADIUS


def write_viewer(
    results: RunResults,
    path: str | os.PathLike[str],
    *,
    field: str = "janus",
    facets: int = 8,
    include_plotlyjs: bool | str = True,
) -> Path:
    """Write the interactive viewer of ``results`` to ``path`` (HTML, atomically).

    Parameters
    ----------
    results
        A run (:func:`rotomorph.io.results.read_results`).
    path
        Destination ``.html``; its folder must exist.
    field
        ``"janus"`` (active/passive halves) or a field name of :func:`viewer_fields`.
    facets
        Facets around each tube segment.
    include_plotlyjs
        ``True`` embeds plotly.js (self-contained, ~4 MB); ``"cdn"`` links it instead.

    Raises
    ------
    InvalidParameterError
        An unknown field, or plotly missing.
    """
    fig = viewer_figure(results, field=field, facets=facets)
    html = fig.to_html(include_plotlyjs=include_plotlyjs, full_html=True, auto_play=False)
    return atomic_write_text(path, html)


def viewer_figure(results: RunResults, *, field: str = "janus", facets: int = 8) -> Any:
    """The plotly figure of :func:`write_viewer`: trace 0 the tubes (``Mesh3d``, one colour
    value per triangle), trace 1 the printed shape, one frame per step."""
    go = _plotly()
    names = viewer_fields(results)
    if field not in names:
        raise InvalidParameterError(
            "field", f"{field!r} is not stored in this run; choose one of {', '.join(names)}"
        )
    s = results.n_steps
    edges = results.edges
    radius = _radius(results)
    frac = results.static.get("active_fraction", 0.5)
    verdicts = assess(results.scalars, results.metadata, s)
    labels = results.step_labels()
    values = None if field == "janus" else _segment_field(results, field)
    if values is not None:
        # the figures' limits: robust, symmetric for signed data, round-off drawn as neutral
        norm = scalar_norm(values.reshape(-1))
        lo, hi = float(norm.vmin or 0.0), float(norm.vmax or 1.0)
        cscale: Any = "RdBu_r"
        unit = results.units.get(field, "")
        cbar = {"title": f"{field} ({unit})" if unit not in ("", "1") else field}
    else:
        lo, hi = 0.0, 1.0
        cscale = [
            [0.0, PASSIVE_COLOUR],
            [0.5, PASSIVE_COLOUR],
            [0.5, ACTIVE_COLOUR],
            [1.0, ACTIVE_COLOUR],
        ]
        cbar = None

    def mesh(k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        normals = results.fields["active_normal"][k] if values is None else None
        quads, _, active, seg = tube_mesh(
            results.positions[k], edges, radius, normals, facets=facets, active_fraction=frac
        )
        m = len(edges)
        ring0 = quads[:, 0].reshape(m, facets, 3)
        ring1 = quads[:, 3].reshape(m, facets, 3)
        verts = np.concatenate([ring0, ring1], axis=1).reshape(-1, 3)
        if values is None:
            inten = np.where(active, 1.0, 0.0) if active is not None else np.zeros(len(seg))
        else:
            inten = values[k][seg]
        # single precision (0.1 µm at 1 m) halves the file; plotly stores typed arrays
        return verts.astype(np.float32), np.repeat(inten, 2).astype(np.float32), seg

    m = len(edges)
    j = np.arange(facets)
    base = (np.arange(m) * 2 * facets)[:, None]
    a0, a1 = base + j, base + (j + 1) % facets
    b0, b1 = a0 + facets, a1 + facets
    tri_i = np.stack([a0, a0], axis=2).reshape(-1).astype(np.int32)
    tri_j = np.stack([a1, b1], axis=2).reshape(-1).astype(np.int32)
    tri_k = np.stack([b1, b0], axis=2).reshape(-1).astype(np.int32)

    def title(k: int) -> str:
        v = verdicts[k] if k < s - 1 else run_verdict(verdicts)
        colour = "#b2182b" if v.verdict == "no" else "black"
        return f"{labels[k]} (step {k}/{s - 1}) — <span style='color:{colour}'>{v.text()}</span>"

    def trace(k: int) -> Any:
        verts, inten, _ = mesh(k)
        return go.Mesh3d(
            x=verts[:, 0],
            y=verts[:, 1],
            z=verts[:, 2],
            i=tri_i,
            j=tri_j,
            k=tri_k,
            intensity=inten,
            intensitymode="cell",
            colorscale=cscale,
            cmin=lo,
            cmax=hi,
            showscale=cbar is not None,
            colorbar=cbar,
            flatshading=False,
            lighting={"ambient": 0.45, "diffuse": 0.7, "specular": 0.3, "roughness": 0.5},
            name="tubes",
            hoverinfo="skip",
        )

    printed = results.positions[0]
    gx, gy, gz = (np.full((m, 3), np.nan) for _ in range(3))
    for c, arr in enumerate((gx, gy, gz)):
        arr[:, 0], arr[:, 1] = printed[edges[:, 0], c], printed[edges[:, 1], c]
    ghost = go.Scatter3d(
        x=gx.reshape(-1),
        y=gy.reshape(-1),
        z=gz.reshape(-1),
        mode="lines",
        line={"color": "rgba(120,120,120,0.5)", "width": 2, "dash": "dash"},
        name="printed shape",
        hoverinfo="skip",
    )
    allp = results.positions.reshape(-1, 3)
    lo3, hi3 = allp.min(axis=0), allp.max(axis=0)
    half = 0.5 * float((hi3 - lo3).max()) + float(np.max(radius))
    mid = 0.5 * (lo3 + hi3)
    axes = {
        c: {"range": [mid[i] - half, mid[i] + half], "title": f"{c} (mm)"}
        for i, c in enumerate("xyz")
    }
    frames = [
        go.Frame(data=[trace(k)], traces=[0], name=str(k), layout={"title": {"text": title(k)}})
        for k in range(s)
    ]
    slider = {
        "active": s - 1,
        "currentvalue": {"prefix": "step "},
        "steps": [
            {
                "label": labels[k],
                "method": "animate",
                "args": [
                    [str(k)],
                    {
                        "mode": "immediate",
                        "frame": {"duration": 0, "redraw": True},
                        "transition": {"duration": 0},
                    },
                ],
            }
            for k in range(s)
        ],
    }
    play = {
        "type": "buttons",
        "showactive": False,
        "x": 0.0,
        "y": 0.0,
        "buttons": [
            {
                "label": "▶ play",
                "method": "animate",
                "args": [None, {"frame": {"duration": 600, "redraw": True}, "fromcurrent": False}],
            },
        ],
    }
    legend_note = (
        f"<span style='color:{ACTIVE_COLOUR}'>■ active half</span> "
        f"<span style='color:{PASSIVE_COLOUR}'>■ passive half</span>"
        if values is None
        else ""
    )
    design_name = str(results.metadata.get("design_name", ""))
    fig = go.Figure(
        data=[trace(s - 1), ghost],
        frames=frames,
        layout={
            "title": {"text": title(s - 1)},
            "scene": {
                "xaxis": axes["x"],
                "yaxis": axes["y"],
                "zaxis": axes["z"],
                "aspectmode": "cube",
            },
            "sliders": [slider],
            "updatemenus": [play],
            "annotations": [
                {
                    "text": f"{design_name} {legend_note}",
                    "showarrow": False,
                    "x": 0.0,
                    "y": 1.0,
                    "xref": "paper",
                    "yref": "paper",
                    "xanchor": "left",
                }
            ],
            "margin": {"l": 0, "r": 0, "t": 60, "b": 0},
        },
    )
    return fig
