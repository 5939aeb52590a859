"""A self-contained interactive HTML 3-D viewer of a run (plotly; optional extra ``[html]``).

:func:`write_viewer` writes one HTML file (plotly.js embedded, no network needed) with the
filaments as tubes, a slider and a play button over the heating ramp, the printed shape as a
grey line and the filaments' names. Tubes are coloured by the Janus sides (interface normal
toward the active half, when the run stores ``active_normal``) or by a stored field (per node or
per segment) on one colour scale for the whole ramp. Each frame's title carries the state's
verdict (:mod:`rotomorph.io.validity`). Frames carry only what changes (see
:func:`viewer_figure`), so the file is plotly.js plus little more than one float32 vertex array
per step.

Every text that comes from the run (filament and design names, field names and units, the
verdict's reasons, step labels) is escaped for plotly's HTML subset
(:func:`rotomorph._text.markup_safe`): a name holding ``<a href=…>`` or ``<span style=…>`` is
shown as those characters, never as a link or styled text. The page links nowhere (no plotly
logo link).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph._text import markup_safe
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.io.results import RunResults
from rotomorph.io.validity import assess, run_verdict
from rotomorph.plot.coarsen import CoarseNetwork, coarsen_network
from rotomorph.plot.shapes import scalar_norm
from rotomorph.plot.tubes import ACTIVE_COLOUR, PASSIVE_COLOUR, tube_mesh

__all__ = ["viewer_fields", "viewer_figure", "write_viewer"]

#: Radius (mm) of tubes when the run stores none.
DEFAULT_RADIUS = 0.3
#: Colour of the printed shape behind the tubes.
GHOST_COLOUR = "rgb(175,175,175)"


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
    html = fig.to_html(
        include_plotlyjs=include_plotlyjs,
        full_html=True,
        auto_play=False,
        config={"displaylogo": False},
    )
    return atomic_write_text(path, html)


def _chain_ends(results: RunResults) -> tuple[list[str], list[int]]:
    """Names and last nodes of the run's filaments (none for a single unnamed one)."""
    chains = results.metadata.get("chains", []) or []
    names = [markup_safe(str(c.get("name") or f"filament {i}")) for i, c in enumerate(chains)]
    return (names, [int(c["stop"]) - 1 for c in chains]) if len(chains) > 1 else ([], [])


def _per_segment(value: Any, e: int, pick: np.ndarray) -> np.ndarray | float:
    """A static per-segment value taken at the coarse segments' middles, or the scalar."""
    v = np.asarray(value, dtype=float)
    return v[pick] if v.ndim == 1 and len(v) == e else float(np.mean(v))


def viewer_figure(
    results: RunResults,
    *,
    field: str = "janus",
    facets: int = 8,
    network: CoarseNetwork | None = None,
) -> Any:
    """The plotly figure of :func:`write_viewer`.

    Trace 0 holds the tubes (``Mesh3d``: the triangles once, one colour value per triangle),
    trace 1 the printed shape, trace 2 (runs of several filaments) their names. Each frame
    carries only what changes over the ramp: the tube vertices (float32) and the labels'
    positions, plus the colour values when they change (a field; the Janus sides do not, the
    tube rings turn with the interface normal). Runs of segments much shorter than the tube
    radius are drawn as coarser segments (:func:`~rotomorph.plot.coarsen.coarsen_network`,
    about one radius long, turning by at most 0.2 rad), which no one sees and which keeps the
    file small. ``network`` gives those coarse segments instead (a figure drawn in parts, such
    as a run streamed step by step, keeps its first part's: the triangles stay the same).
    """
    go = _plotly()
    names = viewer_fields(results)
    if field not in names:
        raise InvalidParameterError(
            "field", f"{field!r} is not stored in this run; choose one of {names!r}"
        )
    s = results.n_steps
    n_fine = len(results.edges)
    fine_radius = _radius(results)
    coarse = (
        network
        if network is not None
        else coarsen_network(results.positions, results.edges, float(np.max(fine_radius)))
    )
    edges, pick = coarse.edges, coarse.middle
    m = len(edges)
    radius = coarse.mean(fine_radius) if isinstance(fine_radius, np.ndarray) else fine_radius
    frac = _per_segment(results.static.get("active_fraction", 0.5), n_fine, pick)
    stored_normals = results.fields.get("active_normal")
    verdicts = assess(results.scalars, results.metadata, s)
    labels = [markup_safe(label) for label in results.step_labels()]
    values = None if field == "janus" else coarse.mean(_segment_field(results, field))
    if values is not None:
        # the figures' limits: robust, symmetric for signed data, round-off drawn as neutral
        norm = scalar_norm(values.reshape(-1))
        lo, hi = float(norm.vmin or 0.0), float(norm.vmax or 1.0)
        cscale: Any = "RdBu_r"
        unit = str(results.units.get(field, ""))
        text = f"{field} ({unit})" if unit not in ("", "1") else field
        cbar = {"title": {"text": markup_safe(text)}}
    else:
        lo, hi = 0.0, 1.0
        cscale = [
            [0.0, PASSIVE_COLOUR],
            [0.5, PASSIVE_COLOUR],
            [0.5, ACTIVE_COLOUR],
            [1.0, ACTIVE_COLOUR],
        ]
        cbar = None

    def mesh(k: int) -> tuple[np.ndarray, np.ndarray]:
        """Vertices ``(2·m·facets, 3)`` float32 and one colour value per triangle."""
        normals = None
        if stored_normals is not None:
            nk = np.asarray(stored_normals[k], dtype=float)[pick]
            normals = nk if np.isfinite(nk).all() else None  # ring frames turn with them
        quads, _, active, seg = tube_mesh(
            results.positions[k], edges, radius, normals, facets=facets, active_fraction=frac
        )
        ring0 = quads[:, 0].reshape(m, facets, 3)
        ring1 = quads[:, 3].reshape(m, facets, 3)
        verts = np.concatenate([ring0, ring1], axis=1).reshape(-1, 3)
        if values is None:
            inten = np.where(active, 1.0, 0.0) if active is not None else np.full(len(seg), 0.5)
        else:
            inten = values[k][seg]
        # single precision: 0.1 µm at 1 m, 4 bytes a number in plotly's typed arrays
        return verts.astype(np.float32), np.repeat(inten, 2).astype(np.float32)

    meshes = [mesh(k) for k in range(s)]
    colours_change = any(not np.array_equal(c, meshes[-1][1]) for _, c in meshes)
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
        verdict = markup_safe(v.text())
        return f"{labels[k]} (step {k}/{s - 1}) — <span style='color:{colour}'>{verdict}</span>"

    def moving(k: int) -> dict[str, Any]:
        verts, inten = meshes[k]
        out: dict[str, Any] = {"x": verts[:, 0], "y": verts[:, 1], "z": verts[:, 2]}
        if colours_change:
            out["intensity"] = inten
        return out

    tubes = go.Mesh3d(
        **moving(s - 1),
        **({} if colours_change else {"intensity": meshes[-1][1]}),
        i=tri_i,
        j=tri_j,
        k=tri_k,
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
        x=gx.reshape(-1).astype(np.float32),
        y=gy.reshape(-1).astype(np.float32),
        z=gz.reshape(-1).astype(np.float32),
        mode="lines",
        line={"color": GHOST_COLOUR, "width": 3},
        name="printed shape",
        hoverinfo="skip",
    )
    chain_names, ends = _chain_ends(results)
    r_max = float(np.max(radius))
    allp = results.positions.reshape(-1, 3)
    lo3, hi3 = allp.min(axis=0), allp.max(axis=0)
    half = 0.5 * (hi3 - lo3) + 2.0 * r_max
    half = np.maximum(half, 0.15 * float(half.max()))  # flat shapes keep some depth
    mid = 0.5 * (lo3 + hi3)
    axes = {
        c: {
            "range": [mid[i] - half[i], mid[i] + half[i]],
            "title": f"{c} (mm)",
            "nticks": max(3, round(8 * half[i] / half.max())),  # ticks that never crowd
        }
        for i, c in enumerate("xyz")
    }
    ratio = half / float(half.max())  # one scale: the same millimetres per pixel on x, y, z
    view = np.array([-0.3, -0.9, 0.6])  # from the front, a little above
    eye = view / np.linalg.norm(view) * 1.2 * float(np.linalg.norm(ratio))  # fits the box

    def names_at(k: int) -> list[dict[str, Any]]:
        """Each filament's name beside its last node, with a leader line (drawn over the
        scene: never hidden by a tube nor clipped by the box)."""
        pos = results.positions[k]
        return [
            {
                "x": float(pos[n, 0]),
                "y": float(pos[n, 1]),
                "z": float(pos[n, 2]),
                "text": name,
                "showarrow": True,
                "arrowhead": 0,
                "arrowcolor": "rgb(90,90,90)",
                "ax": 40,
                "ay": -25,
                "font": {"size": 13, "color": "black"},
                "bgcolor": "rgba(255,255,255,0.7)",
            }
            for name, n in zip(chain_names, ends, strict=True)
        ]

    def frame_layout(k: int) -> dict[str, Any]:
        layout: dict[str, Any] = {"title": {"text": title(k)}}
        if chain_names:
            layout["scene"] = {"annotations": names_at(k)}
        return layout

    frames = [
        go.Frame(data=[go.Mesh3d(**moving(k))], traces=[0], name=str(k), layout=frame_layout(k))
        for k in range(s)
    ]
    slider = {
        "active": s - 1,
        "x": 0.1,
        "len": 0.88,
        "y": 0.0,
        "yanchor": "top",
        "pad": {"t": 10, "b": 10},
        "currentvalue": {"prefix": "heating: ", "font": {"size": 14}},
        "font": {"size": 12},
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
        "xanchor": "left",
        "yanchor": "top",
        "pad": {"t": 45},
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
    design_name = markup_safe(str(results.metadata.get("design_name", "")))
    fig = go.Figure(
        data=[tubes, ghost],
        frames=frames,
        layout={
            "title": {"text": title(s - 1)},
            "scene": {
                "xaxis": axes["x"],
                "yaxis": axes["y"],
                "zaxis": axes["z"],
                "aspectmode": "manual",
                "aspectratio": dict(zip("xyz", (float(v) for v in ratio), strict=True)),
                "camera": {"eye": dict(zip("xyz", (float(v) for v in eye), strict=True))},
                "annotations": names_at(s - 1) if chain_names else [],
            },
            "sliders": [slider],
            "updatemenus": [play],
            "showlegend": False,
            "annotations": [
                {
                    "text": f"{design_name} {legend_note} "
                    f"<span style='color:{GHOST_COLOUR}'>━ printed shape</span>",
                    "showarrow": False,
                    "x": 0.0,
                    "y": 1.0,
                    "xref": "paper",
                    "yref": "paper",
                    "xanchor": "left",
                    "font": {"size": 14},
                }
            ],
            "margin": {"l": 10, "r": 10, "t": 70, "b": 110},
        },
    )
    return fig
