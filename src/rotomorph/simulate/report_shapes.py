"""The paper report's 3-D figures: free filaments and heated lattices as Janus tubes.

Each figure draws its states as shaded tubes with the active and passive halves in two colours
(:func:`rotomorph.plot.tubes.plot_tube_panels`), on one scale for all its panels, with the
printed shape as a ghost. The active side of a free filament follows its material frame: the
printed interface normal keeps its angle to the material directors, which are carried along the
heated shape by parallel transport and turned by the natural twist (the construction of
:func:`rotomorph.simulate.free_shape.free_equilibrium`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from rotomorph._typing import FloatArray
from rotomorph.geometry import rotate_about_tangent, space_parallel_directors, unit
from rotomorph.materials import FilamentModel

if TYPE_CHECKING:  # matplotlib is imported only when a figure is drawn
    from matplotlib.figure import Figure

__all__ = ["filament_shapes_figure", "free_shape_normals", "lattice_tube_figure"]

#: Resolution of the report's tube figures (dots per inch).
DPI = 130.0


def free_shape_normals(
    program: Any, model: FilamentModel, points: FloatArray, temperature: float = 175.0
) -> FloatArray:
    """Interface normal toward the active half per segment ``(E, 3)`` of a free heated shape.

    Parameters
    ----------
    program
        The :class:`~rotomorph.design.program.PrintProgram` printed.
    model
        The filament model that gave ``points``.
    points
        The free shape ``(N, 3)`` (mm) of
        :func:`~rotomorph.simulate.validation.free_shape` (same program, model, temperature).
    temperature
        Heating temperature (°C).
    """
    from rotomorph.materials.natural import natural_field
    from rotomorph.rod.model import Model

    field = natural_field(program, temperature=temperature, model=model)
    rod = Model.from_field(program.points, field)
    _, _, twist = rod.integrated_natural()
    t0 = unit(np.diff(np.asarray(program.points, dtype=float), axis=0))
    m1_0 = np.asarray(rod.directors, dtype=float)
    n0 = np.asarray(program.interface_normals, dtype=float)
    beta = np.arctan2(
        np.einsum("ij,ij->i", n0, np.cross(t0, m1_0)), np.einsum("ij,ij->i", n0, m1_0)
    )
    x = np.asarray(points, dtype=float)
    t = unit(np.diff(x, axis=0))
    d = space_parallel_directors(x, first=m1_0[0])
    m1 = rotate_about_tangent(d, t, np.r_[0.0, np.cumsum(twist)])
    return np.cos(beta)[:, None] * m1 + np.sin(beta)[:, None] * np.cross(t, m1)


def filament_shapes_figure(
    shapes: Mapping[tuple[str, float], tuple[Any, FloatArray, FloatArray]],
) -> Figure:
    """Free filaments heated to 175 °C, one row per material, one column per ω*.

    Parameters
    ----------
    shapes
        ``(material label, ω*) -> (program, shape (N, 3) mm, normals (E, 3))``.
    """
    from rotomorph.plot.tubes import TubePanel, plot_tube_panels

    labels = sorted({k[0] for k in shapes}, reverse=True)
    omegas = sorted({k[1] for k in shapes})
    panels = []
    for label in labels:
        for w in omegas:
            prog, x, normals = shapes[(label, w)]
            printed = np.asarray(prog.points, dtype=float)
            ratio = np.linalg.norm(x[-1] - x[0]) / np.linalg.norm(printed[-1] - printed[0])
            n = len(printed)
            panels.append(
                TubePanel(
                    positions=x,
                    edges=np.c_[np.arange(n - 1), np.arange(1, n)],
                    radius=float(prog.radius),
                    normals=normals,
                    title=f"{label}, ω* = {w:g}\nL/L0 = {ratio:.2f}",
                    ghost=printed,
                    active_fraction=float(prog.active_fraction),
                )
            )
    length = float(np.linalg.norm(np.diff(printed, axis=0), axis=1).sum())
    return plot_tube_panels(
        panels,
        columns=len(omegas),
        panel_size=3.2,
        elev=24.0,
        azim=-70.0,
        facets=12,
        dpi=DPI,
        suptitle=f"Free filaments printed straight ({length:.0f} mm), heated to 175 °C: "
        "shapes predicted from the calibrated model",
    )


def lattice_tube_figure(
    lattice: Any,
    result: Any,
    values: FloatArray,
    *,
    title: str,
    title_colour: str = "k",
) -> Figure:
    """A heated lattice at the end of its ramp: Janus sides from above at an angle and from the
    side, and the relative curvature change (paper Fig. 4A/D), one scale for all three.

    Parameters
    ----------
    lattice
        The :class:`~rotomorph.design.lattices.Lattice` printed.
    result
        Its :class:`~rotomorph.lattice.heating.HeatingResult`.
    values
        Per-node (κ − κᵢ)/κᵢ at the end of the ramp ``(N,)`` (κᵢ: curvature as printed).
    title, title_colour
        Figure title and its colour.
    """
    from dataclasses import replace

    from rotomorph.lattice.model import interface_normals
    from rotomorph.plot.shapes import RELATIVE_CHANGE_LABEL, relative_change_norm, segment_values
    from rotomorph.plot.tubes import TubePanel, plot_tube_panels
    from rotomorph.simulate.paraview import centreline_curvature
    from rotomorph.simulate.run_data import active_normals

    k = len(result.positions) - 1
    edges = np.asarray(lattice.network.edges)
    normals = None
    positions, ghost, drawn = result.positions[k], result.positions[0], edges
    seg = segment_values(values, edges)
    if result.states:  # the printed interface normals carried with the material frame
        ends = (result.states[0], result.states[k])
        normals = active_normals(ends, interface_normals(lattice))[1][1]
        if lattice.layers > 1:  # every layer of the printed stack, on its material director
            from rotomorph.contact.stack import layer_edges, layer_points
            from rotomorph.lattice.admissibility import lattice_stack

            stack = lattice_stack(lattice)
            m1 = [s.material_directors()[0] for s in ends]
            ghost = layer_points(ghost, edges, m1[0], stack.offsets)
            positions = layer_points(positions, edges, m1[1], stack.offsets)
            drawn = layer_edges(len(edges), stack.count)
            normals = np.tile(normals, (stack.count, 1))
            seg = np.tile(seg, stack.count)
    oblique = TubePanel(
        positions=positions,
        edges=drawn,
        radius=float(lattice.radius),
        normals=normals,
        title="active and passive halves"
        + (f" ({lattice.layers} layers)" if drawn is not edges else ""),
        ghost=ghost,
        active_fraction=float(lattice.active_fraction),
    )
    side = replace(oblique, title="side view", view=(4.0, -90.0))
    chains = [np.asarray(c) for c in lattice.edge_chains]
    printed = segment_values(centreline_curvature(result.positions[:1], chains)[0], edges)
    printed = np.tile(printed, len(seg) // len(printed))  # every layer of a stack alike
    field = replace(oblique, values=seg, title="relative curvature change")
    return plot_tube_panels(
        [oblique, side, field],
        columns=3,
        panel_size=3.6,
        facets=10,
        dpi=DPI,
        norm=relative_change_norm(seg, printed),
        label=RELATIVE_CHANGE_LABEL,
        cmap="coolwarm",
        suptitle=title,
        suptitle_colour=title_colour,
    )
