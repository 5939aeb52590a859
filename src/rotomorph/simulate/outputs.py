"""Files of one simulation run: HDF5 results, summary, figures, ParaView series and a GIF.

:func:`write_run` writes a :class:`~rotomorph.simulate.design.DesignSimulation` into a folder;
:func:`plot_run` draws the figures from a :class:`~rotomorph.io.results.RunResults` (so
``rotomorph plot RESULT.h5`` re-creates exactly what ``rotomorph simulate`` drew). Every file is
written atomically; the folder must exist.

Folder layout::

    results.h5              positions per step, scalars, fields, design, metadata
    summary.json            sizes, first/last scalars, units, metadata
    figures/shape_initial.png, figures/shape_final.png     3-D views (coloured)
    figures/end_to_end_ratio.png                          filaments: L/L0 over temperature
    figures/lattice_initial.png, figures/lattice_final.png lattices: top/side, Fig. 4 colouring
    figures/lattice_metrics.png                           lattices: area, curvature vs strain
    morphing.gif            the morphing, one frame per step
    paraview/morphing.pvd   + morphing_0000.vtp …, point data per step
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph.io.results import RunResults, summarize, write_results, write_summary
from rotomorph.io.vtk import network_lines, write_vtp_series

__all__ = ["colour_field", "plot_run", "write_run", "write_vtk"]


def colour_field(results: RunResults) -> tuple[str | None, str]:
    """Name of the per-node field used to colour shapes and its label, if any."""
    if "relative_curvature_change" in results.fields:
        return "relative_curvature_change", "(κ − κ_i)/κ_i"
    if "curvature" in results.fields:
        return "curvature", "κ (1/mm)"
    return None, ""


def _kind(results: RunResults) -> str:
    return str(results.metadata.get("kind", "filaments"))


def _labels(results: RunResults) -> list[str]:
    sc = results.scalars
    if "temperature" in sc:
        return [f"T = {t:.0f} °C" for t in sc["temperature"]]
    if "actuation" in sc:
        return [f"x = {x:.2f}" for x in sc["actuation"]]
    return [f"step {i}" for i in range(results.n_steps)]


def _filament_figure(results: RunResults) -> Any:
    from rotomorph.plot.figure import new_figure

    fig = new_figure(6.0, 4.2)
    ax = fig.add_subplot()
    t = results.scalars.get("temperature", np.arange(results.n_steps, dtype=float))
    ratios = results.fields.get("end_to_end_ratio_per_filament")
    if ratios is None:
        ratios = results.scalars["end_to_end_ratio"][:, None]
    chains = results.metadata.get("chains", [])
    for j in range(ratios.shape[1]):
        name = chains[j]["name"] if j < len(chains) else f"filament {j}"
        ax.plot(t, ratios[:, j], marker="o", ms=3, label=name)
    ax.set_xlabel("temperature (°C)" if "temperature" in results.scalars else "step")
    ax.set_ylabel("L/L0 (–)")
    ax.set_title("End-to-end ratio over heating")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    return fig


def _lattice_metrics_figure(results: RunResults) -> Any:
    from rotomorph.plot.figure import new_figure

    sc = results.scalars
    fig = new_figure(10.0, 4.0)
    left, right = fig.subplots(1, 2)
    x = sc.get("actuation", np.arange(results.n_steps, dtype=float))
    left.plot(x, sc["area_ratio"], "o-", ms=3)
    left.set_xlabel("actuation parameter x (–)")
    left.set_ylabel("A/A0 (–)")
    left.set_title("Projected area")
    left.grid(alpha=0.3)
    right.plot(sc["edge_strain"], sc["characteristic_curvature"], "ko-", ms=3)
    right.set_xlabel("mean edge strain (–)")
    right.set_ylabel("√|k1 k2| (1/mm)")
    sign = sc.get("gaussian_sign", np.zeros(1))[-1]
    right.set_title(f"Characteristic curvature (final Gaussian sign {sign:+.0f})")
    right.grid(alpha=0.3)
    return fig


def plot_run(
    results: RunResults, folder: str | os.PathLike[str], *, gif: bool = True
) -> list[Path]:
    """Draw the run's figures (and GIF) into ``folder`` (created if missing); return the paths."""
    from rotomorph.plot.animate import animate_gif
    from rotomorph.plot.figure import save_figure
    from rotomorph.plot.shapes import plot_lattice_views, plot_network_3d

    out = Path(folder)
    figs = out / "figures"
    figs.mkdir(parents=True, exist_ok=True)
    name, label = colour_field(results)
    values = None if name is None else results.fields[name]
    pos, edges = results.positions, results.edges
    paths = []
    vmin: float | None
    vmax: float | None
    if values is not None:
        finite = values[np.isfinite(values)]
        lim = float(np.max(np.abs(finite))) if finite.size else 1.0
        signed = finite.size and finite.min() < 0
        vmin, vmax = (-lim, lim) if signed else (0.0, lim or 1.0)
    else:
        vmin = vmax = None
    for tag, k in (("initial", 0), ("final", results.n_steps - 1)):
        v = None if values is None else values[k]
        fig = plot_network_3d(
            pos[k],
            edges,
            v,
            vmin=vmin,
            vmax=vmax,
            label=label,
            title=f"{tag} ({_labels(results)[k]})",
        )
        paths.append(save_figure(fig, figs / f"shape_{tag}.png"))
    if _kind(results) == "lattice":
        for tag, k in (("initial", 0), ("final", results.n_steps - 1)):
            v = None if values is None else values[k]
            fig = plot_lattice_views(pos[k], edges, v, vmin=vmin, vmax=vmax, label=label, title=tag)
            paths.append(save_figure(fig, figs / f"lattice_{tag}.png"))
        paths.append(save_figure(_lattice_metrics_figure(results), figs / "lattice_metrics.png"))
    else:
        paths.append(save_figure(_filament_figure(results), figs / "end_to_end_ratio.png"))
    if gif:
        paths.append(
            animate_gif(
                pos,
                edges,
                out / "morphing.gif",
                values=values,
                labels=_labels(results),
                view="3d",
            )
        )
    return paths


def write_vtk(results: RunResults, path: str | os.PathLike[str]) -> Path:
    """ParaView series of the run (``.pvd`` + one ``.vtp`` per step) with its per-node fields."""
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    n = results.positions.shape[1]
    data = {k: v for k, v in results.fields.items() if v.ndim == 2 and v.shape[1] == n}
    times = results.scalars.get("temperature", results.scalars.get("actuation"))
    return write_vtp_series(
        target,
        results.positions,
        network_lines(results.edges, results.branch),
        times=None if times is None else list(map(float, times)),
        point_data=data,
    )


def write_run(sim: Any, folder: str | os.PathLike[str], *, gif: bool = True) -> list[Path]:
    """Write every file of a simulation run into ``folder`` (must exist); return the paths."""
    out = Path(folder)
    results = sim.run_results()
    paths = [
        write_results(
            out / "results.h5",
            design=sim.design,
            edges=sim.edges,
            branch=sim.branch,
            positions=sim.positions,
            scalars=sim.scalars,
            fields=sim.fields,
            units=sim.units,
            metadata=results.metadata,
        )
    ]
    paths.append(write_summary(out / "summary.json", summarize(results)))
    paths += plot_run(results, out, gif=gif)
    paths.append(write_vtk(results, out / "paraview" / "morphing.pvd"))
    return paths
