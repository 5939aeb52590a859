"""Figures of a sweep table: a curve with spread, a morphology phase diagram, a heat map.

* One parameter: :func:`plot_curve` draws each output against it; when several points share a
  parameter value (other parameters sampled too, or repeats) the mean is drawn with a band from
  the smallest to the largest value and ± one standard deviation as error bars.
* Two parameters: :func:`plot_phase_diagram` colours each point by its morphology class
  (straight, twisted rod, helix, coil; grey crosses for runs that did not succeed, hollow
  markers for non-physical states), and :func:`plot_heatmap` shows a numeric output as a
  heat map (on a grid, cells; otherwise coloured points).

Only ``status == "ok"`` rows enter curves and heat maps, and those whose state is not physical
(``physical`` false) are ringed in red (curves) or crossed (heat maps); they take the table
(:class:`pyarrow.Table`), not the run files.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from rotomorph.errors import InvalidParameterError
from rotomorph.plot.figure import new_figure, save_figure

__all__ = [
    "MORPHOLOGY_COLOURS",
    "plot_curve",
    "plot_heatmap",
    "plot_phase_diagram",
    "plot_sweep",
]

#: Colour of each morphology class in phase diagrams.
MORPHOLOGY_COLOURS = {
    "straight": "#9e9e9e",
    "twisted rod": "#1b9e77",
    "helix": "#7570b3",
    "coil": "#d95f02",
}


def _column(table: Any, name: str) -> list[Any]:
    if name not in table.column_names:
        raise InvalidParameterError("column", f"no column {name!r}; have {table.column_names}")
    return table.column(name).to_pylist()


def _unit(table: Any, name: str) -> str:
    meta = table.schema.field(name).metadata or {}
    unit = meta.get(b"unit", b"").decode()
    return f" ({unit})" if unit and unit != "1" else ""


def _ok(table: Any) -> np.ndarray:
    return np.array([s == "ok" for s in _column(table, "status")], dtype=bool)


def _unphysical(table: Any) -> np.ndarray:
    """Rows whose state failed a check (``physical`` false: unconverged, unstable or passing
    through itself); unknown (null) is not counted as failed."""
    if "physical" not in table.column_names:
        return np.zeros(table.num_rows, dtype=bool)
    return np.array([p is False for p in _column(table, "physical")], dtype=bool)


_RED = "#b2182b"
_NOT_PHYSICAL = "not physical (see physical_reason)"


def plot_curve(
    table: Any,
    parameter: str,
    outputs: Sequence[str],
    *,
    measured: Sequence[tuple[Any, str]] = (),
    group: str | None = None,
    title: str = "",
) -> Any:
    """Outputs against one parameter, with spread where points share a value.

    Parameters
    ----------
    table
        A sweep table.
    parameter
        Column of the x axis (numeric).
    outputs
        Numeric output columns, one panel each.
    measured
        ``(MeasuredTable, output)`` pairs drawn as points with error bars on the panel of
        ``output`` (e.g. the paper's measurements); or ``(MeasuredTable, "output@value")`` to
        draw them in the colour of that ``group`` value.
    group
        A second parameter column: one curve per value of it (instead of pooling its values
        into the spread).
    title
        Figure title.
    """
    ok = _ok(table)
    x_all = np.array(_column(table, parameter), dtype=float)
    g_all = _column(table, group) if group is not None else [None] * len(x_all)
    levels = list(dict.fromkeys(g_all))
    fig = new_figure(4.6 * len(outputs), 3.8)
    axes = np.atleast_1d(fig.subplots(1, len(outputs)))
    for ax, out in zip(axes, outputs, strict=True):
        y_all = np.array([np.nan if v is None else v for v in _column(table, out)], dtype=float)
        for k, level in enumerate(levels):
            colour = f"C{k}"
            keep = ok & np.isfinite(y_all) & np.isfinite(x_all)
            keep &= np.array([g == level for g in g_all])
            label = "rotomorph" if group is None else f"{group} = {level}"
            _draw_curve(ax, x_all[keep], y_all[keep], colour, label)
            for data, target in measured:
                name, _, at = target.partition("@")
                drawn_once = not at and k == 0
                if name == out and (drawn_once or (group is not None and at == str(level))):
                    ax.errorbar(
                        data.x,
                        data.value,
                        yerr=data.spread,
                        fmt="s",
                        mfc="white",
                        mec=colour if at else "k",
                        ecolor=colour if at else "k",
                        ms=6,
                        capsize=3,
                        label=f"measured ({data.name})",
                    )
        bad = ok & _unphysical(table) & np.isfinite(y_all) & np.isfinite(x_all)
        if bad.any():  # drawn as results would lie: ring them, as every figure flags them
            ax.plot(x_all[bad], y_all[bad], "o", ms=8, mfc="none", mec=_RED, label=_NOT_PHYSICAL)
        n_bad = int((~ok).sum())
        if n_bad:
            ax.text(
                0.02, 0.02, f"{n_bad} run(s) not ok", transform=ax.transAxes, fontsize=8, color="r"
            )
        ax.set_xlabel(parameter + _unit(table, parameter))
        ax.set_ylabel(out + _unit(table, out))
        ax.grid(alpha=0.3)
    _one_legend(fig, list(axes))
    if title:
        fig.suptitle(title)
    fig.set_layout_engine("constrained")
    return fig


def _one_legend(fig: Any, axes: Sequence[Any]) -> None:
    """One legend for all panels (each entry once): inside a single panel, below several;
    none where the only entry would be the one curve."""
    entries: dict[str, Any] = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            entries.setdefault(label, handle)
    if list(entries) in ([], ["rotomorph"]):
        return
    if len(axes) == 1:
        axes[0].legend(entries.values(), entries.keys(), fontsize=7)
        return
    fig.legend(
        entries.values(),
        entries.keys(),
        loc="outside lower center",
        ncol=min(len(entries), 4),
        fontsize=8,
        frameon=False,
    )


def _draw_curve(ax: Any, x: np.ndarray, y: np.ndarray, colour: str, label: str) -> None:
    xs = np.unique(x)
    groups = [y[x == v] for v in xs]
    mean = np.array([g.mean() for g in groups])
    if any(len(g) > 1 for g in groups):
        lo = np.array([g.min() for g in groups])
        hi = np.array([g.max() for g in groups])
        sd = np.array([g.std() for g in groups])
        ax.fill_between(xs, lo, hi, color=colour, alpha=0.2, label=f"{label}: min–max")
        ax.errorbar(
            xs, mean, yerr=sd, fmt="o-", ms=3, color=colour, capsize=2, label=f"{label}: mean ± sd"
        )
    else:
        ax.plot(xs, mean, "o-", ms=3, color=colour, label=label)


def plot_phase_diagram(
    table: Any, x: str, y: str, *, output: str = "morphology", title: str = ""
) -> Any:
    """Morphology class of every point over two parameters (module docstring)."""
    xs = np.array(_column(table, x), dtype=float)
    ys = np.array(_column(table, y), dtype=float)
    labels = _column(table, output)
    physical = _column(table, "physical")
    ok = _ok(table)
    fig = new_figure(8.0, 4.8)
    ax = fig.add_subplot()
    for name, colour in MORPHOLOGY_COLOURS.items():
        sel = ok & np.array([lab == name for lab in labels])
        if not sel.any():
            continue
        solid = sel & np.array([p is not False for p in physical])
        hollow = sel & ~solid
        ax.scatter(xs[solid], ys[solid], s=60, marker="s", color=colour, label=name)
        if hollow.any():
            ax.scatter(
                xs[hollow],
                ys[hollow],
                s=60,
                marker="s",
                facecolors="none",
                edgecolors=colour,
                label=f"{name} (self-intersecting)",
            )
    unlabelled = ok & np.array([lab is None for lab in labels])
    if unlabelled.any():  # solved, but no helix describes the shape (a gently bent arc)
        ax.scatter(xs[unlabelled], ys[unlabelled], s=40, marker="o", facecolors="none",
                   edgecolors="0.4", label="no helix fits (a gently bent arc, other)")  # fmt: skip
    if (~ok).any():
        ax.scatter(xs[~ok], ys[~ok], s=40, marker="x", color="0.4", label="invalid / failed")
    ax.set_xlabel(x + _unit(table, x))
    ax.set_ylabel(y + _unit(table, y))
    ax.set_title(title or f"{output} over ({x}, {y})")
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0.0)
    ax.grid(alpha=0.2)
    return fig


def plot_heatmap(table: Any, x: str, y: str, output: str, *, title: str = "") -> Any:
    """A numeric output over two parameters: cells on a full grid, coloured points otherwise."""
    ok = _ok(table)
    xs = np.array(_column(table, x), dtype=float)
    ys = np.array(_column(table, y), dtype=float)
    zs = np.array([np.nan if v is None else v for v in _column(table, output)], dtype=float)
    zs[~ok] = np.nan
    fig = new_figure(6.4, 4.8)
    ax = fig.add_subplot()
    ux, uy = np.unique(xs), np.unique(ys)
    mesh: Any
    if len(ux) * len(uy) == len(xs) and len(ux) > 1 and len(uy) > 1:
        grid = np.full((len(uy), len(ux)), np.nan)
        grid[np.searchsorted(uy, ys), np.searchsorted(ux, xs)] = zs
        mesh = ax.pcolormesh(_edges(ux), _edges(uy), grid, shading="flat", cmap="viridis")
    else:
        mesh = ax.scatter(xs, ys, c=zs, s=50, cmap="viridis")
    bad = ok & _unphysical(table)
    if bad.any():
        ax.scatter(xs[bad], ys[bad], s=40, marker="x", color=_RED, label=_NOT_PHYSICAL)
        ax.legend(fontsize=7, loc="upper right")
    fig.colorbar(mesh, ax=ax, label=output + _unit(table, output))
    ax.set_xlabel(x + _unit(table, x))
    ax.set_ylabel(y + _unit(table, y))
    ax.set_title(title or f"{output} over ({x}, {y})")
    return fig


def _edges(v: np.ndarray) -> np.ndarray:
    mid = 0.5 * (v[1:] + v[:-1])
    return np.concatenate([[v[0] - (mid[0] - v[0])], mid, [v[-1] + (v[-1] - mid[-1])]])


def plot_sweep(
    table: Any, parameters: Sequence[str], outputs: Sequence[str], folder: str | os.PathLike[str]
) -> list[Path]:
    """The standard figures of a sweep into ``folder`` (created): see module docstring.

    One numeric parameter: ``curve.png`` of the numeric outputs. Two: ``phase_diagram.png``
    (when ``morphology`` is an output) and ``heatmap_<output>.png`` per numeric output.
    More parameters: nothing (choose two columns and call the functions directly).
    """
    out = Path(folder)
    out.mkdir(parents=True, exist_ok=True)
    numeric = [o for o in outputs if table.schema.field(o).type in ("double", "int64")]
    paths: list[Path] = []
    if len(parameters) == 1 and numeric:
        fig = plot_curve(table, parameters[0], numeric)
        paths.append(save_figure(fig, out / "curve.png"))
    elif len(parameters) == 2:
        x, y = parameters
        for o in outputs:
            if o.rsplit(".", 1)[-1] == "morphology":
                paths.append(
                    save_figure(
                        plot_phase_diagram(table, x, y, output=o), out / "phase_diagram.png"
                    )
                )
        for o in numeric:
            safe = o.replace("[", "_").replace("]", "").replace(".", "_")
            paths.append(save_figure(plot_heatmap(table, x, y, o), out / f"heatmap_{safe}.png"))
    return paths
