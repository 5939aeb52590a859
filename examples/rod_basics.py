"""Rod basics
==========

Rod basics: build a filament, give it a natural curvature-twist field, support it, load it,
solve, and check the answer against the exact helix.

Run: ``python examples/rod_basics.py [--nodes N] [--figure PATH]``. Prints one JSON object per
line; ``--figure`` draws both solved shapes (PNG).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from rotomorph.analysis.shape import fit_helix
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.static import StaticResult, solve_static


def free_helix(n: int) -> dict:
    """A straight, free filament with kappa_bar = 0.5/mm, tau_bar = 0.3/mm becomes a helix."""
    result = solve_free_helix(n)
    fit = fit_helix(result.positions)
    k, t = 0.5, 0.3
    return {
        "case": "free_helix",
        "n_nodes": n,
        "iterations": result.iterations,
        "radius": fit.radius,
        "radius_exact": k / (k * k + t * t),
        "pitch": abs(fit.pitch),
        "pitch_exact": 2 * np.pi * t / (k * k + t * t),
    }


def solve_free_helix(n: int) -> StaticResult:
    """The free filament of :func:`free_helix`, solved."""
    radius, young = 0.3, 1.0  # mm, MPa
    inertia = np.pi * radius**4 / 4  # mm^4
    s = np.linspace(0.0, 30.0, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],  # nodes (mm)
        bending_stiffness1=young * inertia,  # B1, N mm^2 (toward the director m1)
        bending_stiffness2=young * inertia,  # B2
        twist_stiffness=young / 3 * 2 * inertia,  # C = G J with G = E/3
        axial_stiffness=young * np.pi * radius**2,  # EA, N
    ).with_natural(curvature1=np.full(n - 2, 0.5), twist=np.full(n - 2, 0.3))  # 1/mm
    return solve_static(model)  # free-free


def drooping_cantilever(n: int) -> dict:
    """A clamped LCE filament (E = 29.67 MPa) sagging under its own weight and a tip load."""
    result = solve_cantilever(n)
    return {
        "case": "cantilever",
        "n_nodes": n,
        "iterations": result.iterations,
        "tip_deflection_mm": float(-result.positions[-1, 2]),
    }


def solve_cantilever(n: int) -> StaticResult:
    """The clamped filament of :func:`drooping_cantilever`, solved."""
    radius, young, length = 0.3, 29.67, 20.0
    inertia = np.pi * radius**4 / 4
    s = np.linspace(0.0, length, n)
    model = Model.chain(
        np.c_[s, 0 * s, 0 * s],
        bending_stiffness1=young * inertia,
        bending_stiffness2=young * inertia,
        twist_stiffness=young / 3 * 2 * inertia,
        axial_stiffness=young * np.pi * radius**2,
    )
    loads = Loads(
        forces=[(n - 1, (0.0, 0.0, -2e-4))],  # N
        gravity=Gravity(density=1.1, area=np.pi * radius**2),
    )
    return solve_static(model, Supports.clamp_ends(n), loads)


def figure(n: int, path: Path) -> None:
    """Both solved shapes: the helix with its exact radius and pitch, and the drooping
    cantilever, each on one scale with its own axes in mm."""
    from rotomorph.plot.figure import new_figure, save_figure

    helix, droop = solve_free_helix(n), solve_cantilever(n)
    row = free_helix(n)
    fig = new_figure(8.0, 5.0)
    top, bottom = fig.subplots(2, 1, height_ratios=[1.0, 1.2])
    # the helix seen from the side of its fitted axis
    fit = fit_helix(helix.positions)
    x = helix.positions - fit.axis_point
    along = x @ fit.axis
    side = np.cross(fit.axis, [0.0, 0.0, 1.0] if abs(fit.axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    across = x @ (side / np.linalg.norm(side))
    top.plot(along, across, "-", color="0.25", lw=1.5, label="rod solver, 101 nodes")
    top.plot(along[::5], across[::5], "o", color="C3", ms=3.5, label="every fifth node")
    r_exact = row["radius_exact"]
    for y in (-r_exact, r_exact):
        top.axhline(y, color="C0", lw=1, ls="--")
    top.plot([], [], "--", color="C0", lw=1, label=f"exact helix radius ±{r_exact:.4f} mm")
    top.set_aspect("equal")
    top.set_xlabel("along the helix axis (mm)")
    top.set_ylabel("across (mm)")
    top.set_title(
        f"Free filament, κ̄ = 0.5/mm, τ̄ = 0.3/mm: radius {row['radius']:.4f} mm (exact "
        f"{row['radius_exact']:.4f}), pitch {row['pitch']:.4f} mm (exact {row['pitch_exact']:.4f})",
        fontsize=9,
    )
    top.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.32), ncol=3,
               frameon=False)  # fmt: skip
    p = droop.positions
    bottom.plot([0.0, p[-1, 0] + 0.5], [0.0, 0.0], color="0.7", lw=1, label="as printed")
    bottom.plot(p[:, 0], p[:, 2], "k-", lw=2, label="clamped: own weight + 0.2 mN at the tip")
    bottom.plot([p[-1, 0]], [p[-1, 2]], "o", color="C3", ms=5)
    bottom.annotate(
        f"tip deflection {-p[-1, 2]:.3f} mm",
        (p[-1, 0], p[-1, 2]),
        xytext=(-150, -6),
        textcoords="offset points",
        va="center",
        arrowprops={"arrowstyle": "->", "color": "0.3"},
        fontsize=9,
    )
    bottom.set_aspect("equal")
    bottom.set_ylim(p[:, 2].min() - 1.0, 1.0)
    bottom.set_xlabel("x (mm)")
    bottom.set_ylabel("z (mm)")
    bottom.set_title("LCE cantilever (E = 29.67 MPa, r = 0.3 mm, 20 mm), side view", fontsize=9)
    bottom.legend(fontsize=8, loc="lower left", frameon=False)
    bottom.grid(alpha=0.3)
    fig.set_layout_engine("constrained")
    save_figure(fig, path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--nodes", type=int, default=101, help="nodes per filament")
    parser.add_argument("--figure", type=Path, help="draw both solved shapes (PNG)")
    args = parser.parse_args(argv)
    for row in (free_helix(args.nodes), drooping_cantilever(args.nodes)):
        print(json.dumps(row))
    if args.figure is not None:
        figure(args.nodes, args.figure)
    return 0


if __name__ == "__main__":
    main()  # always 0; not SystemExit, which would end a documentation build running it
