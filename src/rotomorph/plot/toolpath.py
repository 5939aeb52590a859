"""Toolpath preview: print paths coloured by the interface angle α, one panel per distinct layer.

Each edge is coloured by α (rad, cyclic colour map, convention of
:mod:`rotomorph.design.program`); small arrows show the in-plane part of the interface normal n
(toward the active half) every few edges, so the active side and its flips are visible at a
glance; a dot marks each start and thin dashed lines the travel between filaments. Layers whose
toolpaths are identical in plan (a lattice printed three times) share one panel. Rendered with
matplotlib's Agg backend and saved atomically.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Sequence
from pathlib import Path as FilePath
from typing import TYPE_CHECKING

import numpy as np

from rotomorph.design.program import PrintProgram
from rotomorph.errors import InvalidParameterError
from rotomorph.io.atomic import atomic_path

if TYPE_CHECKING:
    from matplotlib.figure import Figure

__all__ = ["plot_toolpath", "save_toolpath_png"]


def plot_toolpath(programs: Sequence[PrintProgram], *, glyphs: int = 40) -> Figure:
    """A matplotlib ``Figure`` previewing ``programs``, one axes per layer.

    Parameters
    ----------
    programs
        Print programs (any layers).
    glyphs
        Approximate number of normal arrows per filament (>= 0).
    """
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    if len(programs) == 0:
        raise InvalidParameterError("programs", "needs at least one PrintProgram")
    groups = _distinct_layers(programs)
    fig = Figure(figsize=(4.2 * len(groups) + 0.8, 4.4), dpi=100)
    axes = fig.subplots(1, len(groups), squeeze=False)[0]
    span = np.ptp(np.concatenate([p.points[:, :2] for p in programs]), axis=0).max() or 1.0
    mappable = None
    for ax, layers in zip(axes, groups, strict=True):
        progs = [p for p in programs if p.layer == layers[0]]
        for a, b in itertools.pairwise(progs):
            ax.plot(*np.stack([a.points[-1, :2], b.points[0, :2]]).T, ls=":", lw=0.7, c="0.5")
        for prog in progs:
            pts = prog.points[:, :2]
            alpha = np.mod(prog.interface_angle + np.pi, 2 * np.pi) - np.pi
            # an (N, 2, 2) array is a valid segment list; the stubs only accept a Sequence
            lc = LineCollection(
                np.stack([pts[:-1], pts[1:]], axis=1),  # type: ignore[arg-type]
                cmap="twilight",
                linewidths=2.0,
            )
            lc.set_array(alpha)
            lc.set_clim(-np.pi, np.pi)
            ax.add_collection(lc)
            mappable = lc
            if glyphs > 0:
                step = max(1, len(pts) // glyphs)
                mid = 0.5 * (pts[:-1] + pts[1:])[::step]
                nrm = prog.interface_normals[::step, :2]
                ax.quiver(
                    mid[:, 0],
                    mid[:, 1],
                    nrm[:, 0],
                    nrm[:, 1],
                    angles="xy",
                    scale_units="xy",
                    scale=25.0 / span,
                    width=0.003,
                    color="k",
                )
            ax.plot(*pts[0], "o", ms=3, color="tab:green")
        ax.set_title(("layer " if len(layers) == 1 else "layers ") + _ranges(layers))
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_aspect("equal")
        ax.autoscale_view()
    if mappable is not None:
        cb = fig.colorbar(mappable, ax=list(axes), shrink=0.8)
        cb.set_label("interface angle α (rad, in each filament's print direction)")
    return fig


def _distinct_layers(programs: Sequence[PrintProgram]) -> list[list[int]]:
    """Layers grouped when their programs have the same plan (x, y, nozzle angle)."""
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


def _ranges(layers: list[int]) -> str:
    if len(layers) > 2 and layers == list(range(layers[0], layers[-1] + 1)):
        return f"{layers[0]}-{layers[-1]}"
    return ", ".join(map(str, layers))


def save_toolpath_png(
    programs: Sequence[PrintProgram], path: str | os.PathLike[str], *, glyphs: int = 40
) -> FilePath:
    """Render :func:`plot_toolpath` to a PNG at ``path`` atomically and return the path."""
    fig = plot_toolpath(programs, glyphs=glyphs)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png")
    return FilePath(path)
