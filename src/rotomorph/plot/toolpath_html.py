"""Interactive toolpath preview: one self-contained HTML page (plotly; optional extra ``[html]``).

A plan view of the programs as the machine prints them (order, direction, z offset: pass
:func:`rotomorph.io.gcode.plan_programs`), one panel per distinct layer as in the PNG preview
(:mod:`rotomorph.plot.toolpath`; layers printed identically share one), the panels' zoom linked:

- every edge coloured by one of three quantities, chosen from a menu: the interface angle α
  (rad shown in degrees, in each filament's print direction, on a cyclic scale), the nozzle's
  turns since the filament's start (the cumulative rotary angle: what the ink lines wind), or
  the rotation rate ω = v dα_n/ds (rad/s);
- short ticks from the path toward the active half (the in-plane part of the interface normal);
- each filament's print-order number at its start (a dot), an arrow along its first millimetres
  and a square at its end; dashed lines for the travel between filaments (lifted, not
  dispensing);
- hovering an edge gives the filament, its name, layer, arc length, height, α, the nozzle angle,
  ω and the speed.

Every text that comes from a design (names, title) is escaped: it is shown as written and never
read as plotly's markup (``<b>``, ``<a href>``) or hover-template syntax (``%{…}``).
"""

from __future__ import annotations

import html
import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_write_text
from rotomorph.plot.toolpath import active_side_ticks, distinct_layers, layer_title

__all__ = ["COLOURINGS", "toolpath_figure", "write_toolpath_html"]

#: Colourings of the edges: key -> (menu label, colour-bar title, plotly colour scale).
COLOURINGS = {
    "alpha": (
        "colour: interface angle α",
        "α (deg), in each<br>filament's print<br>direction",
        "Twilight",
    ),
    "turns": ("colour: nozzle turns", "nozzle turns<br>since the<br>filament's start", "Portland"),
    "omega": ("colour: rotation rate ω", "ω = v dα<sub>n</sub>/ds<br>(rad/s)", "Portland"),
}
_BINS = 32  # colour steps of the edges (a trace per step and colouring)


def _go() -> Any:
    try:
        import plotly.graph_objects as go
    except ImportError as err:
        raise InvalidParameterError(
            "preview",
            f"the interactive preview needs plotly: pip install 'rotomorph[html]' ({err})",
        ) from None
    return go


def escape(text: object) -> str:
    """``text`` as plotly shows it literally: HTML escaped, and ``%`` so that no hover template
    reads it (``%{x}``)."""
    return html.escape(str(text), quote=True).replace("%", "&#37;")


def _edge_values(prog: PrintProgram) -> dict[str, np.ndarray]:
    """Per edge: α (deg, wrapped), nozzle turns since the start, ω (rad/s), and the hover data."""
    nozzle = 0.5 * (prog.nozzle_angle[1:] + prog.nozzle_angle[:-1])
    alpha = np.degrees(np.mod(prog.interface_angle + np.pi, 2 * np.pi) - np.pi)
    omega = np.diff(prog.nozzle_angle) / prog.path.edge_lengths * prog.speed[:-1]
    s = 0.5 * (prog.arc_length[1:] + prog.arc_length[:-1])
    return {
        "alpha": alpha,
        "turns": (nozzle - prog.nozzle_angle[0]) / (2 * np.pi),
        "omega": omega,
        "s": s,
        "nozzle": np.degrees(nozzle),
        "speed": prog.speed[:-1],
        "z": 0.5 * (prog.points[1:, 2] + prog.points[:-1, 2]),
    }


def _limits(key: str, values: list[np.ndarray]) -> tuple[float, float]:
    if key == "alpha":
        return -180.0, 180.0
    top = max(float(np.max(np.abs(v))) for v in values)
    top = top if top > 1e-9 else 1.0
    return -top, top


def _segments(points: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """x, y of polylines (each ``(k, 2)``) joined by NaN gaps, for one line trace."""
    if not points:
        return np.array([]), np.array([])
    gap = np.full((1, 2), np.nan)
    xy = np.concatenate([p for pts in points for p in (pts, gap)])
    return xy[:, 0], xy[:, 1]


def toolpath_figure(
    programs: Sequence[PrintProgram],
    *,
    names: Sequence[str] | None = None,
    title: str = "",
    lift: float | None = None,
    colour: str = "alpha",
) -> Any:
    """The plotly figure of :func:`write_toolpath_html` (module docstring).

    Parameters
    ----------
    programs
        Print programs in print order, as printed (:func:`rotomorph.io.gcode.plan_programs`).
    names
        One label per program (e.g. the design's filament names), shown escaped on hover.
    title
        Shown escaped above the panels (e.g. the design's name and the machine's).
    lift
        Travel height above the part (mm) for the travel's hover text; None: not stated.
    colour
        The colouring shown first: a key of :data:`COLOURINGS` (the page's menu switches).

    Raises
    ------
    InvalidParameterError
        No programs, names of another length, an unknown colouring, or plotly missing.
    """
    if colour not in COLOURINGS:
        raise InvalidParameterError(
            "colour", f"must be one of {', '.join(COLOURINGS)}; got {colour!r}"
        )
    go = _go()
    from plotly.colors import sample_colorscale
    from plotly.subplots import make_subplots

    n = len(programs)
    if n == 0:
        raise InvalidParameterError("programs", "needs at least one PrintProgram")
    if names is not None and len(names) != n:
        raise InvalidParameterError("names", f"needs one name per program ({n}); got {len(names)}")
    labels = [escape(names[k]) + " " if names is not None else "" for k in range(n)]
    groups = distinct_layers(programs)
    cols = min(len(groups), 3)
    rows = -(-len(groups) // cols)
    fig = make_subplots(
        rows=rows,
        cols=cols,
        subplot_titles=[layer_title(g) for g in groups],
        horizontal_spacing=0.06,
        vertical_spacing=0.08 / rows,
    )
    edges = [_edge_values(p) for p in programs]
    limits = {key: _limits(key, [e[key] for e in edges]) for key in COLOURINGS}
    xy = np.concatenate([p.points[:, :2] for p in programs])
    span = float(np.ptp(xy, axis=0).max()) or 1.0
    tick = span / 70.0  # length of the active-side ticks (mm)
    glyph_every = span / 70.0  # their spacing along a filament (mm)
    order = {id(p): k for k, p in enumerate(programs)}
    roles: list[tuple[str, str | None]] = []  # per trace: (kind, colouring or None)

    def add(trace: Any, row: int, col: int, kind: str, colouring: str | None = None) -> None:
        fig.add_trace(trace, row=row, col=col)
        roles.append((kind, colouring))

    for g, layers in enumerate(groups):
        row, col = g // cols + 1, g % cols + 1
        first = [p for p in programs if p.layer == layers[0]]
        ks = [order[id(p)] for p in first]
        also = {  # the same filament printed again in the group's other layers
            k: [order[id(p)] for lay in layers[1:] for p in programs if p.layer == lay][
                i :: len(ks)
            ]
            for i, k in enumerate(ks)
        }
        # a grey outline keeps every path visible where a colour scale is pale
        x, y = _segments([programs[k].points[:, :2] for k in ks])
        add(
            go.Scatter(
                x=x,
                y=y,
                mode="lines",
                line={"color": "rgb(170,170,170)", "width": 5},
                hoverinfo="skip",
                showlegend=False,
            ),
            row,
            col,
            "outline",
        )
        for key, (_, _, scale) in COLOURINGS.items():
            lo, hi = limits[key]
            per_bin: list[list[np.ndarray]] = [[] for _ in range(_BINS)]
            for k in ks:
                pts = programs[k].points[:, :2]
                b = np.clip(((edges[k][key] - lo) / (hi - lo) * _BINS).astype(int), 0, _BINS - 1)
                cuts = np.flatnonzero(np.diff(b)) + 1  # runs of edges in one colour step
                for start, stop in zip([0, *cuts], [*cuts, len(b)], strict=True):
                    per_bin[b[start]].append(pts[start : stop + 1])
            for b, segs in enumerate(per_bin):
                if not segs:
                    continue
                x, y = _segments(segs)
                rgb = sample_colorscale(scale, [(b + 0.5) / _BINS])[0]
                add(
                    go.Scatter(
                        x=x,
                        y=y,
                        mode="lines",
                        line={"color": rgb, "width": 3},
                        hoverinfo="skip",
                        showlegend=False,
                        visible=key == colour,
                    ),
                    row,
                    col,
                    "edges",
                    key,
                )
        # the active side: ticks from edge midpoints along the in-plane interface normal
        ticks = []
        for k in ks:
            mid, tip = active_side_ticks(programs[k], glyph_every, tick)
            ticks += list(np.stack([mid, tip], axis=1))
        x, y = _segments(ticks)
        add(
            go.Scatter(
                x=x,
                y=y,
                mode="lines",
                line={"color": "black", "width": 1},
                name="toward the active half",
                legendgroup="active",
                showlegend=g == 0,
                hoverinfo="skip",
            ),
            row,
            col,
            "ticks",
        )
        # travel: from where the previous filament ended to each start (lifted, not dispensing)
        travel = [
            np.stack([programs[k - 1].points[-1, :2], programs[k].points[0, :2]])
            for k in ks
            if k > 0
        ]
        x, y = _segments(travel)
        lifted = f" (lifted {lift:g} mm above the part)" if lift is not None else " (lifted)"
        add(
            go.Scatter(
                x=x,
                y=y,
                mode="lines",
                line={"color": "rgb(120,120,120)", "width": 1.2, "dash": "dash"},
                name="travel" + lifted,
                legendgroup="travel",
                showlegend=g == 0,
                hoverinfo="skip",
            ),
            row,
            col,
            "travel",
        )
        # hover on every edge midpoint: what the machine does there
        for k in ks:
            prog, e = programs[k], edges[k]
            mid = 0.5 * (prog.points[1:, :2] + prog.points[:-1, :2])
            again = "".join(f", {j + 1}" for j in also[k])
            layer = ", ".join(str(programs[j].layer) for j in [k, *also[k]])
            head = f"<b>{k + 1}{again}.</b> {labels[k]}(layer {layer})"
            data = np.column_stack(
                [e["s"], e["z"], e["alpha"], e["nozzle"], e["turns"], e["omega"], e["speed"]]
            )
            add(
                go.Scatter(
                    x=mid[:, 0],
                    y=mid[:, 1],
                    mode="markers",
                    marker={"size": 7, "color": "rgba(0,0,0,0)"},
                    customdata=data,
                    hovertemplate=head
                    + "<br>s = %{customdata[0]:.2f} mm, z = %{customdata[1]:.3f} mm"
                    "<br>α = %{customdata[2]:.1f}°"
                    "<br>nozzle %{customdata[3]:.1f}° (%{customdata[4]:+.2f} turns)"
                    "<br>ω = %{customdata[5]:.3g} rad/s, v = %{customdata[6]:.3g} mm/s"
                    "<extra></extra>",
                    showlegend=False,
                ),
                row,
                col,
                "hover",
            )
        ends = np.array([programs[k].points[-1, :2] for k in ks])
        add(
            go.Scatter(
                x=ends[:, 0],
                y=ends[:, 1],
                mode="markers",
                marker={"symbol": "square", "size": 6, "color": "rgb(90,90,90)"},
                name="end",
                legendgroup="end",
                showlegend=g == 0,
                hovertext=[f"{k + 1}. {labels[k]}ends here" for k in ks],
                hoverinfo="text",
            ),
            row,
            col,
            "ends",
        )
        # print order: a numbered dot at each start, an arrow along the start, a square at the end
        starts = np.array([programs[k].points[0, :2] for k in ks])
        shared: dict[tuple[float, float], list[int]] = {}  # filaments that start at one point
        for k, (x0, y0) in zip(ks, starts, strict=True):
            shared.setdefault((round(float(x0), 3), round(float(y0), 3)), []).append(k)
        numbers = {ids[0]: ", ".join(str(k + 1) for k in ids) for ids in shared.values()}
        add(
            go.Scatter(
                x=starts[:, 0],
                y=starts[:, 1],
                mode="markers+text",
                marker={
                    "size": 8,
                    "color": "rgb(0,140,60)",
                    "line": {"color": "white", "width": 1},
                },
                text=[numbers.get(k, "") for k in ks],
                textposition="top left",
                textfont={"size": 12, "color": "rgb(0,90,40)"},
                name="start (print order)",
                legendgroup="start",
                showlegend=g == 0,
                hovertext=[f"{k + 1}. {labels[k]}starts here" for k in ks],
                hoverinfo="text",
            ),
            row,
            col,
            "starts",
        )
        arrows, angles = [], []
        for k in ks:
            prog = programs[k]
            i = int(np.searchsorted(prog.arc_length, min(0.06 * span, 0.4 * prog.arc_length[-1])))
            i = min(max(i, 1), len(prog.points) - 1)
            d = prog.points[i, :2] - prog.points[i - 1, :2]
            arrows.append(prog.points[i, :2])
            angles.append(90.0 - float(np.degrees(np.arctan2(d[1], d[0]))))  # clockwise from up
        arrows_xy = np.array(arrows)
        add(
            go.Scatter(
                x=arrows_xy[:, 0],
                y=arrows_xy[:, 1],
                mode="markers",
                marker={"symbol": "arrow", "size": 11, "angle": angles, "color": "rgb(0,140,60)"},
                name="print direction",
                legendgroup="direction",
                showlegend=g == 0,
                hoverinfo="skip",
            ),
            row,
            col,
            "arrows",
        )
    # one colour bar per colouring (a trace with no points shows the scale)
    for key, (_, bar, scale) in COLOURINGS.items():
        lo, hi = limits[key]
        fig.add_trace(
            go.Scatter(
                x=[None],
                y=[None],
                mode="markers",
                marker={
                    "color": [lo, hi],
                    "colorscale": scale,
                    "cmin": lo,
                    "cmax": hi,
                    "showscale": True,
                    "colorbar": {"title": {"text": bar}, "len": 0.8},
                },
                hoverinfo="skip",
                showlegend=False,
                visible=key == colour,
            )
        )
        roles.append(("colourbar", key))
    buttons = [
        {
            "label": label,
            "method": "restyle",
            "args": [{"visible": [c is None or c == key for _, c in roles]}],
        }
        for key, (label, _, _) in COLOURINGS.items()
    ]
    for i in range(1, len(groups) + 1):  # equal scales, zoom linked across the panels
        suffix = "" if i == 1 else str(i)
        fig.layout[f"yaxis{suffix}"].update(scaleanchor=f"x{suffix}", scaleratio=1, title="y (mm)")
        fig.layout[f"xaxis{suffix}"].update(title="x (mm)")
        if i > 1:
            fig.layout[f"xaxis{suffix}"].update(matches="x")
            fig.layout[f"yaxis{suffix}"].update(matches="y")
    n_layers = len({p.layer for p in programs})
    heading = f"{escape(title)}: " if title else ""
    fig.update_layout(
        title={
            "text": f"{heading}{n} filament(s), {n_layers} layer(s): the toolpath as printed",
            "x": 0.01,
        },
        height=140 + 620 * rows,
        template="plotly_white",
        legend={"orientation": "h", "y": -0.06 if rows == 1 else -0.03, "x": 0.0},
        updatemenus=[
            {
                "buttons": buttons,
                "direction": "right",
                "type": "buttons",
                "x": 1.0,
                "xanchor": "right",
                "y": 1.0 + 0.09 / rows,
                "yanchor": "bottom",
                "showactive": True,
                "active": list(COLOURINGS).index(colour),
            }
        ],
        margin={"l": 60, "r": 20, "t": 110, "b": 80},
    )
    fig.layout.meta = {"roles": [list(r) for r in roles]}
    return fig


def write_toolpath_html(
    programs: Sequence[PrintProgram],
    path: str | os.PathLike[str],
    *,
    names: Sequence[str] | None = None,
    title: str = "",
    lift: float | None = None,
    colour: str = "alpha",
    include_plotlyjs: bool | str = True,
) -> Path:
    """Write the interactive preview of ``programs`` to ``path`` (HTML, atomically).

    ``include_plotlyjs=True`` embeds plotly.js (a self-contained page that needs no network,
    about 5 MB); ``"cdn"`` links it instead. See :func:`toolpath_figure` for the rest.
    """
    fig = toolpath_figure(programs, names=names, title=title, lift=lift, colour=colour)
    page = fig.to_html(
        include_plotlyjs=include_plotlyjs,
        full_html=True,
        config={"responsive": True, "displaylogo": False, "scrollZoom": True},
    )
    return atomic_write_text(path, page)
