"""Figures of an inverse design: target vs achieved, error map, print program, convergence."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from rotomorph.inverse.filament import FilamentDesign
from rotomorph.inverse.lattice import LatticeDesign, SurfaceTarget, rigid_motion, surface_misfit
from rotomorph.inverse.simplify import CONVENTION, SimpleProgram
from rotomorph.plot.figure import new_figure, save_figure

__all__ = ["filament_figure", "inverse_figures"]


def _equal_3d(ax, pts) -> None:  # type: ignore[no-untyped-def]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    c, r = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo))
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")


def filament_figure(design: FilamentDesign, program: SimpleProgram | None = None) -> Any:
    """Target vs achieved shape and the print program of a filament design (a Figure).

    With ``program`` (the printed design) the shape is that design's and the program panels
    show its segments, in the design file's convention (:data:`CONVENTION`), over the
    per-vertex solution they simplify.
    """
    tgt = design.target
    ach = design.achieved if program is None else program.achieved
    rms = design.rms_error if program is None else program.rms_error
    rel = design.rms_error_rel if program is None else program.rms_error_rel
    stable = design.stable if program is None else program.stable
    err = np.linalg.norm(ach - tgt, axis=1)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(tgt, axis=0), axis=1))])
    fig = new_figure(12, 5.6, dpi=150)
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot(*tgt.T, color="0.6", lw=6, alpha=0.35, label="target")
    sc = ax.scatter(*ach.T, c=err, cmap="viridis", s=4, vmin=0.0, vmax=max(float(err.max()), 1e-3))
    ax.plot(*ach.T, color="k", lw=0.8, label="designed, simulated")
    _equal_3d(ax, np.vstack([tgt, ach]))
    ax.legend(loc="upper left")
    fig.colorbar(sc, ax=ax, shrink=0.6, pad=0.12, label="distance to target (mm)")
    unstable = stable is False  # the verifying equilibrium: flagged, not a result
    ax.set_title(
        f"RMS error {rms:.3g} mm ({100 * rel:.2g} % of L)"
        + ("\nNOT PHYSICAL: the simulated shape is not a stable minimum" if unstable else ""),
        color="#b2182b" if unstable else "k",
    )
    ax2 = fig.add_subplot(2, 2, 2)
    ax3 = fig.add_subplot(2, 2, 4, sharex=ax2)
    thin: dict[str, Any] = {"color": "0.6", "lw": 0.8}
    ax2.plot(s, design.speed, **thin, label="per-vertex solution")
    ax3.plot(s, design.rotation_number, **thin, label="per-vertex solution")
    if program is not None:
        shown = ""
        for seg in program.segments:
            x = [seg.target_start, seg.target_start + seg.target_length]
            ax2.plot(x, [seg.speed] * 2, color="tab:blue", lw=2)
            if seg.flip:
                ax3.axvspan(*x, color="tab:orange", alpha=0.4, lw=0)
                continue
            ax3.plot(x, [seg.rotation_number] * 2, color="tab:red", lw=2)
            if seg.handedness != shown:  # label where the handedness starts or changes
                ax3.annotate(
                    seg.handedness, (x[0], seg.rotation_number), xytext=(2, 3),
                    textcoords="offset points", fontsize=7, color="0.25",
                )  # fmt: skip
                shown = seg.handedness
        ax2.plot([], [], color="tab:blue", lw=2, label="printed segments")
        ax3.plot([], [], color="tab:red", lw=2, label="printed segments")
        if any(seg.flip for seg in program.segments):
            from matplotlib.patches import Patch

            ax3.add_artist(ax3.legend(handles=[Patch(color="tab:orange", alpha=0.4)],
                                      labels=["flip of the active side"], loc="lower left",
                                      fontsize=7))  # fmt: skip
        ax2.set_title(_wrap(program.text()), fontsize=8)
    top_v = max(float(np.max(design.speed)), *(g.speed for g in getattr(program, "segments", ())))
    ax2.set_ylim(0.0, 1.2 * top_v)  # from zero: one setting reads as one, not as a zoomed wiggle
    top_w = max(float(np.max(np.abs(design.rotation_number))), 0.01)
    if program is not None:
        top_w = max(top_w, *(abs(g.rotation_number) for g in program.settings))
    ax3.set_ylim(-1.35 * top_w, 1.35 * top_w)
    ax3.axhline(0.0, color="0.5", lw=0.6)
    ax2.set_ylabel("print speed v (mm/s)")
    ax2.legend(loc="best", fontsize=7)
    ax2.grid(alpha=0.3)
    bad = np.concatenate([[False], ~design.reachable, [False]])
    if bad.any():
        lim = max(float(np.max(np.abs(design.rotation_number))), 0.01)
        ax3.fill_between(
            s, -lim, lim, where=bad, color="tab:purple", alpha=0.15, label="unreachable"
        )
    ax3.set_xlabel("arc length along the target (mm)")
    ax3.set_ylabel("nozzle rotation number ω*")
    ax3.legend(loc="best", fontsize=7)
    ax3.grid(alpha=0.3)
    fig.text(0.5, 0.005, _wrap(CONVENTION, 150), ha="center", va="bottom", fontsize=7, color="0.3")
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    return fig


def _wrap(text: str, width: int = 90) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width))


def _filament(design: FilamentDesign, folder: Path, program: SimpleProgram | None) -> list[Path]:
    return [save_figure(filament_figure(design, program), folder / "target_vs_achieved.png")]


def _lattice(design: LatticeDesign, folder: Path) -> list[Path]:
    out = []
    lat = design.lattice
    if isinstance(design.target, SurfaceTarget):
        out.append(_on_surface(design, design.target, folder))
    fig = new_figure(6, 4, dpi=150)
    ax = fig.add_subplot(1, 1, 1)
    h = design.objective_history
    ax.semilogy(np.arange(1, len(h) + 1), np.where(np.isfinite(h), h, np.nan), "o-", ms=3)
    ax.set_xlabel("objective evaluation")
    ax.set_ylabel("objective J")
    ax.grid(alpha=0.3, which="both")
    ax.set_title("convergence of the adjoint optimisation")
    fig.tight_layout()
    out.append(save_figure(fig, folder / "objective.png"))
    fig = new_figure(5.5, 5.5, dpi=150)
    ax = fig.add_subplot(1, 1, 1)
    ref = lat.network.nodes
    speeds = design.speeds
    for e, chain in enumerate(lat.edge_chains):
        width = 0.5 + 3.5 * speeds[e] / max(float(speeds.max()), 1e-9)
        ax.plot(*ref[chain, :2].T, color="tab:red" if design.modes[e] > 0 else "tab:blue", lw=width)
    ax.set_aspect("equal")
    ax.set_title(
        "printed pattern: red expanding, blue contracting\n"
        f"line width ∝ print speed ({speeds.min():.2f}–{speeds.max():.2f} mm/s)"
    )
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    fig.tight_layout()
    out.append(save_figure(fig, folder / "pattern.png"))
    return out


def _on_surface(design: LatticeDesign, target: SurfaceTarget, folder: Path) -> Path:
    lat = design.lattice
    size = lat.spacing * (lat.n - 1)
    _, _, p = surface_misfit(design.positions, target, size)
    x = design.positions
    y = rigid_motion(p, x - x.mean(axis=0))
    z_t, _, _ = target.height(y[:, 0], y[:, 1])
    err = y[:, 2] - z_t
    fig = new_figure(13, 5, dpi=150)
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    gx = np.linspace(y[:, 0].min(), y[:, 0].max(), 30)
    gy = np.linspace(y[:, 1].min(), y[:, 1].max(), 30)
    mx, my = np.meshgrid(gx, gy, indexing="ij")
    mz, _, _ = target.height(mx, my)
    ax.plot_surface(mx, my, mz, color="0.75", alpha=0.35, linewidth=0)
    for a, b in lat.network.edges:
        ax.plot(*y[[a, b]].T, color="k", lw=0.8)
    _equal_3d(ax, y)
    ax.set_title(f"{design.target.description}: designed lattice (lines) on the target")
    ax2 = fig.add_subplot(1, 2, 2)
    lim = max(float(np.max(np.abs(err))), 0.01 * size)
    sc = ax2.scatter(y[:, 0], y[:, 1], c=err, cmap="RdBu_r", vmin=-lim, vmax=lim, s=6)
    ax2.set_aspect("equal")
    ax2.set_xlabel("x (mm)")
    ax2.set_ylabel("y (mm)")
    ax2.set_title(
        f"height error of every node (mm)\nRMS at the compared nodes {design.misfit_rms:.3g} mm"
    )
    fig.colorbar(sc, ax=ax2, shrink=0.8)
    fig.tight_layout()
    return save_figure(fig, folder / "target_vs_achieved.png")


def inverse_figures(
    result: FilamentDesign | LatticeDesign,
    folder: str | Path,
    program: SimpleProgram | None = None,
) -> list[Path]:
    """Write the figures of an inverse design into ``folder``; returns the paths.

    ``program``: a filament's printed design (:class:`~rotomorph.inverse.simplify.SimpleProgram`).
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(result, FilamentDesign):
        return _filament(result, folder, program)
    return _lattice(result, folder)
