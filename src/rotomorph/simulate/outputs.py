"""Files of one simulation run: HDF5 results, summary, figures, a movie and VTK files.

:func:`write_run` writes a :class:`~rotomorph.simulate.design.DesignSimulation` into a folder
(created if missing); :func:`plot_run` draws the figures from a
:class:`~rotomorph.io.results.RunResults` alone, so ``rotomorph plot RUN/results.h5 -o
RUN/figures`` re-creates exactly what ``rotomorph simulate`` drew. Every file is written
atomically.

Folder layout::

    results.h5              positions per step, scalars, fields, static arrays, print programs
    summary.json            verdict, per-filament results, first/last scalars, units, metadata
    figures/shapes.png      shaded Janus tubes, one common scale (filaments: one panel each;
                            lattices: printed, last physical step, end of ramp)
    figures/ramp.png        filaments: states across the heating ramp
    figures/end_to_end_ratio.png                filaments: L/L0 over temperature
    figures/lattice_views.png                   lattices: top/side coloured by (κ − κ_i)/κ_i
    figures/lattice_field.png                   lattices: the tubes of shapes.png coloured by
                                                (κ − κ_i)/κ_i on the scale of the physical states
    figures/lattice_metrics.png                 lattices: area, curvature vs strain
    figures/morphing.mp4    the morphing (GIF where no ffmpeg is installed)
    paraview/               ParaView series (:mod:`rotomorph.simulate.paraview`): centre lines,
                            segments, Janus tube surfaces with an ``active`` flag, one set of
                            array names with units for every run kind, and ``show_janus.py``

States that are not physical are flagged in every figure title (:mod:`rotomorph.io.validity`).
"""

from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph.io.results import RunResults, summarize, write_results, write_summary
from rotomorph.io.validity import StepVerdict, assess, run_verdict
from rotomorph.io.vtk import network_lines
from rotomorph.simulate.paraview import write_vtk

#: Phase messages of the writing steps (a command line shows them; silent by default).
phase_log = logging.getLogger("rotomorph.progress")
logger = logging.getLogger(__name__)

__all__ = [
    "colour_field",
    "plot_run",
    "run_line",
    "write_run",
    "write_run_results",
    "write_vtk",
]

#: Tube radius (mm) when a results file does not store one.
DEFAULT_RADIUS = 0.3
_RED = "#b2182b"


def colour_field(results: RunResults) -> tuple[str | None, str]:
    """Name of the per-node field used to colour shapes and its label, if any."""
    from rotomorph.plot.shapes import RELATIVE_CHANGE_LABEL

    if "relative_curvature_change" in results.fields:
        return "relative_curvature_change", RELATIVE_CHANGE_LABEL
    if "curvature" in results.fields:
        return "curvature", "curvature κ (1/mm)"
    return None, ""


def _colour_norm(results: RunResults, name: str, values: np.ndarray) -> Any:
    """Colour limits of per-segment ``values`` of field ``name`` (the relative curvature
    change on the values where the lattice was printed clearly curved)."""
    from rotomorph.plot.shapes import relative_change_norm, scalar_norm, segment_values
    from rotomorph.simulate.paraview import centreline_curvature

    if name != "relative_curvature_change":
        return scalar_norm(values)
    lines = network_lines(results.edges, results.branch)
    printed = centreline_curvature(results.positions[:1], lines)[0]
    printed_seg = segment_values(printed, results.edges)
    return relative_change_norm(values, np.broadcast_to(printed_seg, values.shape))


def _kind(results: RunResults) -> str:
    return str(results.metadata.get("kind", "filaments"))


def _verdicts(results: RunResults) -> list[StepVerdict]:
    return assess(results.scalars, results.metadata, results.n_steps)


def _state_title(results: RunResults, k: int, verdicts: list[StepVerdict]) -> tuple[str, str]:
    """Figure title of step ``k`` and its colour: never "final", the verdict always."""
    last = results.n_steps - 1
    where = "printed" if k == 0 else ("end of heating ramp" if k == last else f"step {k}/{last}")
    v = verdicts[k] if k < last else run_verdict(verdicts)
    colour = _RED if v.verdict == "no" else "k"
    outside = extrapolation_text(results)
    title = f"{where}, {results.step_labels()[k]} — {v.text()}"
    return (title + ("\n" + outside if outside else ""), colour)


def _chains(results: RunResults) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(name, node indices, segment indices) per filament."""
    out = []
    edges = results.edges
    for i, c in enumerate(results.metadata.get("chains", [])):
        nodes = np.arange(int(c["start"]), int(c["stop"]))
        segs = np.flatnonzero((edges[:, 0] >= nodes[0]) & (edges[:, 0] <= nodes[-1]))
        out.append((str(c.get("name", f"filament {i}")), nodes, segs))
    if not out:
        out.append(("", np.arange(results.positions.shape[1]), np.arange(len(edges))))
    return out


def _segment_normals(results: RunResults, k: int, segs: np.ndarray) -> np.ndarray | None:
    n = results.fields.get("active_normal")
    if n is None:
        return None
    v = np.asarray(n[k][segs], dtype=float)
    return v if np.isfinite(v).all() else None


def _segment_radius(results: RunResults, segs: np.ndarray) -> np.ndarray | float:
    r = results.static.get("radius")
    if r is None or len(r) != len(results.edges):
        return DEFAULT_RADIUS
    v = np.asarray(r, dtype=float)[segs]
    return v if np.all(np.isfinite(v) & (v > 0)) else DEFAULT_RADIUS


def _fraction(results: RunResults, segs: np.ndarray) -> np.ndarray | float:
    f = results.static.get("active_fraction")
    if f is None or len(f) != len(results.edges):
        return 0.5
    v = np.asarray(f, dtype=float)[segs]
    return v if np.all((v >= 0) & (v <= 1)) else 0.5


def _filament_caption(results: RunResults, i: int, k: int) -> str:
    """Panel title of filament ``i`` at step ``k``: name, L/L0 and, where it fits, the shape."""
    chains = results.metadata.get("chains", [])
    name = chains[i]["name"] if i < len(chains) else ""
    ratios = results.fields.get("end_to_end_ratio_per_filament")
    parts = [name] if name else []
    if ratios is not None and i < ratios.shape[1]:
        parts.append(f"L/L0 = {ratios[k, i]:.2f}")
    info = results.metadata.get("filaments", [])
    if k == results.n_steps - 1 and i < len(info):
        helix = info[i].get("helix")
        if helix:
            parts.append(
                f"{info[i].get('morphology', 'helix')}, fit rms {helix['rms_residual_mm']:.2g} mm"
            )
        verdict = (info[i].get("physical") or {}).get("verdict")
        if verdict == "no":
            parts.append("NOT PHYSICAL")
    return "\n".join([parts[0], " · ".join(parts[1:])] if len(parts) > 1 else parts)


def _filament_panels(results: RunResults, k: int, rows: list[int] | None = None) -> list[Any]:
    from rotomorph.plot.tubes import TubePanel

    panels = []
    for i, (_, nodes, segs) in enumerate(_chains(results)):
        if rows is not None and i not in rows:
            continue
        local = results.edges[segs] - nodes[0]
        panels.append(
            TubePanel(
                positions=results.positions[k][nodes],
                edges=local,
                radius=_segment_radius(results, segs),
                normals=_segment_normals(results, k, segs),
                title=_filament_caption(results, i, k),
                ghost=results.positions[0][nodes] if k > 0 else None,
                active_fraction=_fraction(results, segs),
            )
        )
    return panels


def _lattice_panel(results: RunResults, k: int, title: str) -> Any:
    from rotomorph.plot.tubes import TubePanel

    segs = np.arange(len(results.edges))
    return TubePanel(
        positions=results.positions[k],
        edges=results.edges,
        radius=_segment_radius(results, segs),
        normals=_segment_normals(results, k, segs),
        title=title,
        ghost=results.positions[0] if k > 0 else None,
        active_fraction=_fraction(results, segs),
    )


def _lattice_steps(results: RunResults, verdicts: list[StepVerdict]) -> list[int]:
    """Printed, the last step that is not known to fail (if earlier), and the end."""
    last = results.n_steps - 1
    ok = next((j - 1 for j, v in enumerate(verdicts) if v.verdict == "no"), last)
    return sorted({0, max(ok, 0), last})


def _shapes_figure(results: RunResults, verdicts: list[StepVerdict]) -> Any:
    from rotomorph.plot.tubes import plot_tube_panels

    last = results.n_steps - 1
    title, colour = _state_title(results, last, verdicts)
    if _kind(results) == "lattice":
        panels = []
        for k in _lattice_steps(results, verdicts):
            v = verdicts[k]
            head = "printed" if k == 0 else ("end of ramp" if k == last else "before the failure")
            mark = (
                ""
                if v.verdict == "yes"
                else ("\nNOT PHYSICAL" if v.verdict == "no" else "\nunverified")
            )
            panels.append(_lattice_panel(results, k, f"{head}, {results.step_labels()[k]}{mark}"))
        return plot_tube_panels(panels, suptitle=title, suptitle_colour=colour, columns=3)
    panels = _filament_panels(results, last)
    return plot_tube_panels(
        panels,
        suptitle=title,
        suptitle_colour=colour,
        columns=min(len(panels), 4),
    )


def _lattice_field_figure(results: RunResults, verdicts: list[StepVerdict]) -> Any | None:
    """The shapes of :func:`_shapes_figure` as tubes coloured by the curvature field (paper
    Fig. 4): one colour scale for all panels, set by the states that pass the checks, that
    round-off cannot stretch."""
    from rotomorph.plot.shapes import segment_values
    from rotomorph.plot.tubes import plot_tube_panels

    name, label = colour_field(results)
    if name is None or results.fields[name].shape[1] != results.positions.shape[1]:
        return None
    steps = _lattice_steps(results, verdicts)
    last = results.n_steps - 1
    values = {k: segment_values(results.fields[name][k], results.edges) for k in steps}
    # the scale of the states that pass the checks (a state that is not physical may reach any
    # value; it is clipped to this scale rather than setting it)
    scaled = [k for k in steps if verdicts[k].verdict != "no" and k > 0] or steps
    norm = _colour_norm(results, name, np.stack([values[k] for k in scaled]))
    panels = []
    for k in steps:
        head = "printed" if k == 0 else ("end of ramp" if k == last else "before the failure")
        mark = {"no": "\nNOT PHYSICAL", "unknown": "\nunverified"}.get(verdicts[k].verdict, "")
        p = _lattice_panel(results, k, f"{head}, {results.step_labels()[k]}{mark}")
        panels.append(type(p)(**{**p.__dict__, "values": values[k]}))
    title, colour = _state_title(results, last, verdicts)
    return plot_tube_panels(
        panels,
        columns=3,
        norm=norm,
        label=label,
        cmap="coolwarm",
        suptitle=title,
        suptitle_colour=colour,
    )


def _filament_step_verdict(results: RunResults, i: int, k: int, verdicts: list[StepVerdict]) -> str:
    """Verdict of filament ``i`` at step ``k``: its own where the run stored one, else the run's."""
    info = results.metadata.get("filaments", [])
    steps = ((info[i].get("physical") or {}).get("steps") if i < len(info) else None) or []
    return str(steps[k]) if k < len(steps) else verdicts[k].verdict


def _ramp_figure(results: RunResults, verdicts: list[StepVerdict]) -> Any:
    """Filaments (up to 4) across the ramp: 4 states each, one common scale."""
    from rotomorph.plot.tubes import plot_tube_panels

    last = results.n_steps - 1
    steps = sorted({round(x) for x in np.linspace(0, last, min(4, last + 1))})
    rows = list(range(min(4, len(_chains(results)))))
    panels = []
    for i in rows:
        for k in steps:
            p = _filament_panels(results, k, rows=[i])[0]
            mark = {"no": " NOT PHYSICAL"}.get(_filament_step_verdict(results, i, k, verdicts), "")
            first = p.title.split("\n")[0]
            label = f"{first}\n{results.step_labels()[k]}{mark}"
            panels.append(type(p)(**{**p.__dict__, "title": label}))
    v = run_verdict(verdicts)
    note = "" if v.verdict == "yes" else f" — {v.text()}"
    outside = extrapolation_text(results)
    note += f"\n{outside}" if outside else ""
    return plot_tube_panels(
        panels,
        columns=len(steps),
        panel_size=3.0,
        suptitle=f"Heating ramp{note}",
        suptitle_colour=_RED if v.verdict == "no" else "k",
    )


def _filament_figure(results: RunResults, verdicts: list[StepVerdict]) -> Any:
    from rotomorph.plot.figure import new_figure

    fig = new_figure(6.0, 4.2)
    ax = fig.add_subplot()
    t = results.scalars.get("temperature", np.arange(results.n_steps, dtype=float))
    ratios = results.fields.get("end_to_end_ratio_per_filament")
    if ratios is None:
        ratios = results.scalars["end_to_end_ratio"][:, None]
    any_bad = False
    colours = [f"C{i}" for i in range(10) if i != 3]  # C3 is red: the rings' colour
    for j, (name, _, _) in enumerate(_chains(results)):
        colour = colours[j % len(colours)]
        ax.plot(t, ratios[:, j], marker="o", ms=3, color=colour, label=name or f"filament {j}")
        # each filament's own verdict per step (as ramp.png), not the run's
        bad = np.array(
            [_filament_step_verdict(results, j, k, verdicts) == "no" for k in range(len(t))]
        )
        if bad.any():
            any_bad = True
            ax.plot(t[bad], ratios[bad, j], "o", ms=7, mfc="none", mec=_RED)
    if any_bad:
        ax.plot([], [], "o", ms=7, mfc="none", mec=_RED, label="not physical")
    ax.set_xlabel("temperature (°C)" if "temperature" in results.scalars else "step")
    ax.set_ylabel("L/L0 (–)")
    v = run_verdict(verdicts)
    outside = extrapolation_text(results)
    ax.set_title(
        "End-to-end ratio over heating"
        + ("" if v.verdict == "yes" else f"\n{v.text()}")
        + (f"\n{outside}" if outside else ""),
        fontsize=10,
        color=_RED if v.verdict == "no" else "k",
    )
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.set_layout_engine("constrained")
    return fig


def _lattice_metrics_figure(results: RunResults, verdicts: list[StepVerdict]) -> Any:
    from rotomorph.plot.figure import new_figure

    sc = results.scalars
    fig = new_figure(10.0, 4.2)
    left, right = fig.subplots(1, 2)
    x = sc.get("actuation", sc.get("temperature", np.arange(results.n_steps, dtype=float)))
    bad = np.array([v.verdict == "no" for v in verdicts])
    left.plot(x, sc["area_ratio"], "o-", ms=3)
    right.plot(sc["edge_strain"], sc["characteristic_curvature"], "ko-", ms=3)
    if bad.any():
        left.plot(
            x[bad], sc["area_ratio"][bad], "o", ms=8, mfc="none", mec=_RED, label="not physical"
        )
        right.plot(
            sc["edge_strain"][bad],
            sc["characteristic_curvature"][bad],
            "o",
            ms=8,
            mfc="none",
            mec=_RED,
            label="not physical",
        )
        left.legend(fontsize=8)
    left.set_xlabel("actuation parameter x (–)" if "actuation" in sc else "temperature (°C)")
    left.set_ylabel("A/A0 (–)")
    left.set_title("Projected area")
    left.grid(alpha=0.3)
    right.set_xlabel("mean edge strain (–)")
    right.set_ylabel("characteristic curvature √|k₁k₂| (1/mm)")
    sign = sc.get("gaussian_sign", np.zeros(1))[-1]
    right.set_title(f"Characteristic curvature (Gaussian sign at end {sign:+.0f})")
    right.grid(alpha=0.3)
    v = run_verdict(verdicts)
    outside = extrapolation_text(results)
    lines = ([] if v.verdict == "yes" else [v.text()]) + ([outside] if outside else [])
    if lines:
        fig.suptitle("\n".join(lines), color=_RED if v.verdict == "no" else "k", fontsize=10)
    fig.set_layout_engine("constrained")
    return fig


def _lattice_views(results: RunResults, verdicts: list[StepVerdict]) -> Any:
    from rotomorph.plot.shapes import plot_lattice_views, segment_values

    name, label = colour_field(results)
    last = results.n_steps - 1
    values = None if name is None else results.fields[name][last]
    norm = None
    if name is not None and values is not None and len(values) == results.positions.shape[1]:
        norm = _colour_norm(results, name, segment_values(values, results.edges))
    title, _ = _state_title(results, last, verdicts)
    return plot_lattice_views(
        results.positions[last], results.edges, values, label=label, title=title, norm=norm
    )


def _movie(results: RunResults, verdicts: list[StepVerdict], path: Path) -> Path:
    from rotomorph.plot.animate import write_movie
    from rotomorph.plot.figure import figure_to_rgb
    from rotomorph.plot.tubes import plot_tube_panels, tube_extent

    lattice = _kind(results) == "lattice"

    def panels(k: int) -> list[Any]:
        if lattice:  # an oblique and a side view: a landscape frame that shows the height
            p = _lattice_panel(results, k, "")
            side = type(p)(**{**p.__dict__, "view": (4.0, -90.0), "title": "side view"})
            return [p, side]
        return _filament_panels(results, k)

    # a box per panel that holds the panel in every frame, so nothing rescales
    per_step = [tube_extent(panels(k)) for k in range(results.n_steps)]
    n_panels = len(per_step[0][0])
    lo = [np.min([s[0][i] for s in per_step], axis=0) for i in range(n_panels)]
    hi = [np.max([s[0][i] for s in per_step], axis=0) for i in range(n_panels)]
    moves = np.max([h - l for l, h in zip(lo, hi, strict=True)], axis=0)
    half = np.max([s[1] for s in per_step], axis=0) + 0.5 * moves
    extent = ([0.5 * (l + h) for l, h in zip(lo, hi, strict=True)], half)
    ncol = min(n_panels, 4)
    size = max(4.0, 12.8 / ncol) if n_panels > 1 else 7.2

    def frame(k: int) -> np.ndarray:
        title, colour = _state_title(results, k, verdicts)
        fig = plot_tube_panels(
            panels(k),
            extent=extent,
            suptitle=title,
            columns=ncol,
            suptitle_colour=colour,
            panel_size=size,
            facets=12,
            dpi=max(100.0, 1280.0 / (ncol * size)),
        )
        return figure_to_rgb(fig)

    return write_movie(frame, results.n_steps, path)


def plot_run(
    results: RunResults, folder: str | os.PathLike[str], *, movie: bool = True
) -> list[Path]:
    """Draw the run's figures (and movie) into ``folder`` (created if missing).

    Files of the same name are replaced (atomically); others in ``folder`` are left alone.
    Returns the paths written.
    """
    from rotomorph.plot.figure import save_figure

    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    verdicts = _verdicts(results)
    paths = [save_figure(_shapes_figure(results, verdicts), out / "shapes.png")]
    if _kind(results) == "lattice":
        paths.append(save_figure(_lattice_views(results, verdicts), out / "lattice_views.png"))
        field_fig = _lattice_field_figure(results, verdicts)
        if field_fig is not None:
            paths.append(save_figure(field_fig, out / "lattice_field.png"))
        paths.append(
            save_figure(_lattice_metrics_figure(results, verdicts), out / "lattice_metrics.png")
        )
    else:
        paths.append(save_figure(_ramp_figure(results, verdicts), out / "ramp.png"))
        paths.append(save_figure(_filament_figure(results, verdicts), out / "end_to_end_ratio.png"))
    if movie:
        paths.append(_movie(results, verdicts, out / "morphing.mp4"))
    return paths


def extrapolation_text(results: RunResults) -> str:
    """``EXTRAPOLATED: why`` where the run lies outside the calibrated range, else ``""``."""
    reasons = results.metadata.get("extrapolation") or []
    return "EXTRAPOLATED: " + "; ".join(str(r) for r in reasons) if reasons else ""


def run_line(results: RunResults) -> str:
    """One line for the command line: per-filament or lattice results, the verdict and, where
    the settings lie outside the calibrated range, why (``EXTRAPOLATED: ...``)."""
    v = run_verdict(_verdicts(results))
    state = "end state " + v.text()
    outside = extrapolation_text(results)
    if outside:
        state += "; " + outside
    if _kind(results) == "lattice":
        sc = results.scalars
        parts = []
        area = float(sc["area_ratio"][-1]) if "area_ratio" in sc else float("nan")
        if np.isfinite(area) and area > 1e-3:
            parts.append(f"area ratio {area:.3f}")
        else:
            parts.append("area ratio not meaningful (projected boundary loop folded onto itself)")
        if "gaussian_sign" in sc:
            parts.append(f"Gaussian sign {sc['gaussian_sign'][-1]:+.0f}")
        return f"{', '.join(parts)}; {state}"
    desc = []
    for f in results.metadata.get("filaments", []):
        text = f"{f['name']}: L/L0 = {f['end_to_end_ratio']:.3f}"
        if f.get("helix"):
            text += f" ({f.get('morphology', 'helix')})"
        if (f.get("physical") or {}).get("verdict") == "no":
            text += " NOT PHYSICAL"
        desc.append(text)
    return f"{', '.join(desc)}; {state}"


def write_run(sim: Any, folder: str | os.PathLike[str], *, movie: bool = True) -> list[Path]:
    """Write every file of a simulation run into ``folder`` (created if missing); return paths.

    ``sim`` is a :class:`~rotomorph.simulate.design.DesignSimulation`, one
    :class:`~rotomorph.simulate.filament.FilamentSimulation` or a list of them.
    """
    from rotomorph.simulate.run_data import describe_run

    return write_run_results(describe_run(as_run(sim)), folder, movie=movie)


def as_run(sim: Any) -> Any:
    """A :class:`~rotomorph.simulate.design.DesignSimulation` of ``sim`` (filament
    simulations are wrapped with :func:`~rotomorph.simulate.design.filaments_simulation`)."""
    from rotomorph.simulate.filament import FilamentSimulation

    if isinstance(sim, FilamentSimulation):
        return sim.to_run()
    if (
        isinstance(sim, list | tuple)
        and sim
        and all(isinstance(s, FilamentSimulation) for s in sim)
    ):
        from rotomorph.simulate.design import filaments_simulation

        return filaments_simulation(sim, {"name": "", "source": "print programs"})
    return sim


def write_run_results(
    results: RunResults, folder: str | os.PathLike[str], *, movie: bool = True
) -> list[Path]:
    """Write the files of a described run (:func:`~rotomorph.simulate.run_data.describe_run`)
    into ``folder`` (created if missing); return the paths."""
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    phase_log.info("writing: results.h5 and summary.json")
    paths = [
        write_results(
            out / "results.h5",
            design=results.design,
            edges=results.edges,
            branch=results.branch,
            positions=results.positions,
            scalars=results.scalars,
            fields=results.fields,
            units=results.units,
            metadata=results.metadata,
            static=results.static,
            programs=results.programs,
        )
    ]
    summary = summarize(results)
    paths.append(write_summary(out / "summary.json", summary))
    phase_log.info("writing: ParaView files")
    paths += write_vtk(results, out / "paraview")
    phase_log.info("writing: figures%s", " and movie" if movie else "")
    try:
        paths += plot_run(results, out / "figures", movie=movie)
    except Exception as err:  # drawing must never cost the computed run
        logger.warning(
            "figures not drawn (%s: %s); results.h5, summary.json and paraview/ are kept: "
            "draw them again with 'rotomorph plot RUN -o FIGURES'",
            type(err).__name__,
            " ".join(str(err).split())[:300],
        )
    # written again last, naming the files actually there (the movie is a GIF without ffmpeg)
    names = sorted(p.relative_to(out).as_posix() for p in out.rglob("*") if p.is_file())
    summary["files"] = sorted({*names, "summary.json"})
    summary["movie"] = next((n for n in names if n.startswith("figures/morphing.")), None)
    write_summary(out / "summary.json", summary)
    return paths
