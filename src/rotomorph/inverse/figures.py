"""Figures of an inverse design: target vs achieved, error map, print program, convergence."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rotomorph.inverse.filament import FilamentDesign
from rotomorph.inverse.lattice import LatticeDesign, SurfaceTarget, rigid_motion, surface_misfit
from rotomorph.plot.figure import new_figure, save_figure

__all__ = ["inverse_figures"]


def _equal_3d(ax, pts) -> None:  # type: ignore[no-untyped-def]
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    c, r = 0.5 * (lo + hi), 0.5 * float(np.max(hi - lo))
    ax.set_xlim(c[0] - r, c[0] + r)
    ax.set_ylim(c[1] - r, c[1] + r)
    ax.set_zlim(c[2] - r, c[2] + r)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")


def _filament(design: FilamentDesign, folder: Path) -> list[Path]:
    out = []
    tgt, ach = design.target, design.achieved
    err = np.linalg.norm(ach - tgt, axis=1)
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(tgt, axis=0), axis=1))])
    fig = new_figure(12, 5.2, dpi=150)
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    ax.plot(*tgt.T, color="0.6", lw=6, alpha=0.35, label="target")
    sc = ax.scatter(*ach.T, c=err, cmap="viridis", s=4, vmin=0.0, vmax=max(float(err.max()), 1e-3))
    ax.plot(*ach.T, color="k", lw=0.8, label="designed, simulated")
    _equal_3d(ax, np.vstack([tgt, ach]))
    ax.legend(loc="upper left")
    fig.colorbar(sc, ax=ax, shrink=0.6, pad=0.12, label="distance to target (mm)")
    unstable = design.stable is False  # the verifying equilibrium: flagged, not a result
    ax.set_title(
        f"RMS error {design.rms_error:.3g} mm ({100 * design.rms_error_rel:.2g} % of L)"
        + ("\nNOT PHYSICAL: the simulated shape is not a stable minimum" if unstable else ""),
        color="#b2182b" if unstable else "k",
    )
    ax2 = fig.add_subplot(2, 2, 2)
    ax2.plot(s, design.speed, color="tab:blue")
    ax2.set_ylabel("print speed v (mm/s)")
    ax2.grid(alpha=0.3)
    ax3 = fig.add_subplot(2, 2, 4, sharex=ax2)
    ax3.plot(s, design.omega_star, color="tab:red", label="ω*")
    ax3.plot(s, design.active_side, color="0.4", lw=0.8, ls="--", label="active side (±1)")
    bad = np.concatenate([[False], ~design.reachable, [False]])
    if bad.any():
        ax3.fill_between(
            s, -2.5, 2.5, where=bad, color="tab:orange", alpha=0.25, label="unreachable"
        )
    ax3.set_xlabel("arc length along the target (mm)")
    ax3.set_ylabel("rotation number ω*")
    ax3.legend(loc="best", fontsize=8)
    ax3.grid(alpha=0.3)
    fig.tight_layout()
    out.append(save_figure(fig, folder / "target_vs_achieved.png"))
    return out


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


def inverse_figures(result: FilamentDesign | LatticeDesign, folder: str | Path) -> list[Path]:
    """Write the figures of an inverse design into ``folder``; returns the paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    if isinstance(result, FilamentDesign):
        return _filament(result, folder)
    return _lattice(result, folder)
