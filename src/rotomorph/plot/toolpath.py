"""Toolpath preview: print paths coloured by the interface angle α, one panel per distinct layer.

Each edge is coloured by α (rad, cyclic colour map, convention of
:mod:`rotomorph.design.program`, in each filament's print direction); short black ticks from
the path point toward the active half (the in-plane part of the interface normal n) at even
spacing and every eighth of a turn of α (:func:`active_side_ticks`), so the active side, its
flips and its turning are visible at a glance; a green dot and number mark
each start in print order, a green arrow the direction, a grey square the end, and dashed grey
lines the travel between filaments. Layers whose toolpaths are identical in plan (a lattice
printed three times) share one panel. Each panel is 6 in square at 150 dpi (900 px), so a
6 × 6 lattice's 1 mm features span about 30 px. Rendered with matplotlib's Agg backend and
saved atomically. The interactive page (:mod:`rotomorph.plot.toolpath_html`) shows the same
with hover values and other colourings.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path as FilePath
from typing import TYPE_CHECKING

import numpy as np

from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

__all__ = [
    "active_side_ticks",
    "distinct_layers",
    "layer_title",
    "plot_toolpath",
    "save_toolpath_png",
]

PANEL_IN = 6.0  # panel width and height (in)
DPI = 150


def plot_toolpath(programs: Sequence[PrintProgram], *, glyphs: int = 70) -> Figure:
    """A matplotlib ``Figure`` previewing ``programs``, one axes per distinct layer.

    Parameters
    ----------
    programs
        Print programs in print order, as printed (any layers).
    glyphs
        Active-side ticks across the width of the part (>= 0): one every ``span / glyphs`` mm
        along each filament.
    """
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    if len(programs) == 0:
        raise InvalidParameterError("programs", "needs at least one PrintProgram")
    groups = distinct_layers(programs)
    cols = min(len(groups), 3)
    rows = -(-len(groups) // cols)
    extent = np.ptp(np.concatenate([p.points[:, :2] for p in programs]), axis=0) + 1e-9
    span = float(extent.max())
    # panels within a PANEL_IN square, shaped like the part (a row of lines is wide and low)
    aspect = float(np.clip(extent[1] / extent[0], 0.3, 1 / 0.3))
    width, height = PANEL_IN * min(1.0, 1.0 / aspect), PANEL_IN * min(1.0, aspect)
    fig = Figure(figsize=(width * cols + 1.6, (height + 1.0) * rows + 0.5), dpi=DPI)
    fig.set_layout_engine("constrained")
    axes = fig.subplots(rows, cols, squeeze=False).reshape(-1)
    for ax in axes[len(groups) :]:
        ax.set_visible(False)
    order = {id(p): k for k, p in enumerate(programs)}
    mappable = None
    for ax, layers in zip(axes, groups, strict=False):
        progs = [p for p in programs if p.layer == layers[0]]
        for prog in progs:
            k = order[id(prog)]
            if k > 0:  # the travel that brings the nozzle here, lifted
                a, b = programs[k - 1].points[-1, :2], prog.points[0, :2]
                ax.plot([a[0], b[0]], [a[1], b[1]], ls=(0, (3, 2)), lw=0.8, c="0.45", zorder=1)
        for prog in progs:
            pts = prog.points[:, :2]
            alpha = np.mod(prog.interface_angle + np.pi, 2 * np.pi) - np.pi
            # an (N, 2, 2) array is a valid segment list; the stubs only accept a Sequence
            segments = np.stack([pts[:-1], pts[1:]], axis=1)
            # a grey outline keeps the path visible where the colour map is pale (α near ±π)
            ax.add_collection(LineCollection(segments, colors="0.6", linewidths=3.4, zorder=2))  # type: ignore[arg-type]
            lc = LineCollection(segments, cmap="twilight", linewidths=2.2, zorder=2.5)  # type: ignore[arg-type]
            lc.set_array(alpha)
            lc.set_clim(-np.pi, np.pi)
            ax.add_collection(lc)
            mappable = lc
            if glyphs > 0:
                ax.add_collection(_ticks(prog, span / glyphs, span / 60.0))
        labels: dict[tuple[float, float], list[str]] = {}  # starts at one point share a label
        for prog in progs:
            _mark_order(ax, prog, span)
            at = (round(float(prog.points[0, 0]), 3), round(float(prog.points[0, 1]), 3))
            labels.setdefault(at, []).append(str(order[id(prog)] + 1))
        for (x, y), numbers in labels.items():
            ax.annotate(
                ", ".join(numbers),
                (x, y),
                xytext=(-3, 3),
                textcoords="offset points",
                ha="right",
                va="bottom",
                fontsize=7.5,
                color="darkgreen",
                bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.75},
                zorder=7,
            )
        ax.set_title(layer_title(layers))
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_aspect("equal")
        ax.autoscale_view()
        ax.margins(0.04)
    if mappable is not None:
        cb = fig.colorbar(mappable, ax=list(axes[: len(groups)]), shrink=0.7, pad=0.01)
        cb.set_label("interface angle α (rad), in each filament's print direction")
        cb.set_ticks(
            [-np.pi, -np.pi / 2, 0, np.pi / 2, np.pi], labels=["-π", "-π/2", "0", "π/2", "π"]
        )
    fig.suptitle(
        "black ticks: toward the active half · dashed: travel (lifted) · square: end\n"
        "green: start, print order (in a shared panel: of its first layer) and direction",
        fontsize=8.5,
        color="0.3",
    )
    return fig


def active_side_ticks(
    prog: PrintProgram, every: float, length: float
) -> tuple[np.ndarray, np.ndarray]:
    """Start and end ``(m, 2)`` (mm) of ticks from edge midpoints toward the active half.

    One tick per ``every`` mm along the filament, and more where the interface turns: one per
    eighth of a turn of α, so a rotating nozzle's active side is drawn turning, never aliased
    into a slow wave; ``length`` (mm) along the in-plane part of the interface normal.
    """
    s = 0.5 * (prog.arc_length[1:] + prog.arc_length[:-1])
    turned = np.concatenate([[0.0], np.cumsum(np.abs(np.diff(prog.interface_angle)))])
    marks = np.floor(s / every + turned / (np.pi / 4))
    at = np.flatnonzero(np.concatenate([[True], np.diff(marks) > 0]))
    mid = 0.5 * (prog.points[1:, :2] + prog.points[:-1, :2])[at]
    return mid, mid + length * prog.interface_normals[at, :2]


def _ticks(prog: PrintProgram, every: float, length: float) -> LineCollection:
    """The :func:`active_side_ticks` of ``prog`` as black segments."""
    from matplotlib.collections import LineCollection

    segments = np.stack(active_side_ticks(prog, every, length), axis=1)
    return LineCollection(segments, colors="k", linewidths=0.7, zorder=3)  # type: ignore[arg-type]


def _mark_order(ax: Axes, prog: PrintProgram, span: float) -> None:
    """Start dot, an arrow along the first millimetres, an end square."""
    start, end = prog.points[0, :2], prog.points[-1, :2]
    i = int(np.searchsorted(prog.arc_length, min(0.05 * span, 0.4 * prog.arc_length[-1])))
    i = min(max(i, 1), len(prog.points) - 1)
    tip, tail = prog.points[i, :2], prog.points[i - 1, :2]
    ax.annotate(
        "",
        xy=(float(tip[0]), float(tip[1])),
        xytext=(float(tail[0]), float(tail[1])),
        arrowprops={"arrowstyle": "-|>", "color": "tab:green", "lw": 1.2, "mutation_scale": 11},
        zorder=5,
    )
    ax.plot(*end, "s", ms=3.0, color="0.35", zorder=6)
    ax.plot(*start, "o", ms=4.5, color="tab:green", mec="white", mew=0.6, zorder=6.5)


def distinct_layers(programs: Sequence[PrintProgram]) -> list[list[int]]:
    """Layers grouped when their programs have the same plan (x, y, nozzle angle, in order)."""
    groups: list[tuple[list[np.ndarray], list[int]]] = []
    for layer in sorted({p.layer for p in programs}):
        plan = [
            np.column_stack([p.points[:, :2], p.nozzle_angle]) for p in programs if p.layer == layer
        ]
        for key, members in groups:
            if len(key) == len(plan) and all(
                a.shape == b.shape and np.allclose(a, b, atol=1e-9)
                for a, b in zip(key, plan, strict=True)
            ):
                members.append(layer)
                break
        else:
            groups.append((plan, [layer]))
    return [members for _, members in groups]


def layer_title(layers: list[int]) -> str:
    """``layer 0``, ``layers 1-2``, ``layers 0, 3``."""
    if len(layers) == 1:
        return f"layer {layers[0]}"
    if len(layers) > 2 and layers == list(range(layers[0], layers[-1] + 1)):
        return f"layers {layers[0]}-{layers[-1]}"
    return "layers " + ", ".join(map(str, layers))


def save_toolpath_png(
    programs: Sequence[PrintProgram], path: str | os.PathLike[str], *, glyphs: int = 70
) -> FilePath:
    """Render :func:`plot_toolpath` to a PNG at ``path`` atomically and return the path."""
    fig = plot_toolpath(programs, glyphs=glyphs)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=DPI)
    return FilePath(path)
