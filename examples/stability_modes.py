"""Stability and eigenmodes
=========================

Is an equilibrium stable, and how does it lose stability? Three cases with exact answers:

1. a perfectly straight clamped–free column under 3x its Euler load: the straight state is an
   equilibrium (by symmetry the gradient vanishes) but a saddle; ``solve_static`` certifies every
   exit point, leaves the saddle along its negative-curvature mode and finds the buckled elastica,
   whose tip is compared with the elliptic-integral solution;
2. the same column held straight: the lowest eigenvalue of the tangent stiffness crosses zero at
   the Euler load ``pi^2 B / (4 L^2)``;
3. a closed ring of a naturally straight rod with natural twist: flat and stable below Michell's
   critical twist ``tau R = sqrt(3) B / C``, unstable above (its lowest mode leaves the plane).

Run: ``python examples/stability_modes.py [--nodes N] [--figure PATH]``. Prints one JSON object
per line; ``--figure`` draws the buckled column and the lowest eigenvalue against the load (PNG).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from rotomorph.rod.cases import EulerColumnCase
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.newton import NewtonOptions
from rotomorph.solve.stability import stability
from rotomorph.solve.static import solve_static

COLUMN = EulerColumnCase()  # clamped-free, L = 10 mm, r = 0.3 mm, E = 1 MPa
YOUNG, RADIUS, LENGTH = COLUMN.young, COLUMN.radius, COLUMN.length  # MPa, mm, mm
BENDING = COLUMN.bending_stiffness  # B, N mm^2
TWIST = BENDING / 1.3  # C = G J with Poisson's ratio 0.3, N mm^2
EULER = COLUMN.euler_load  # clamped-free Euler load, N
column = COLUMN.model  # its clamped first edge is centred on the origin (the clamp)
elastica_tip = COLUMN.elastica_tip  # tip (x, lateral) / L of the elastica


def buckled_column(n: int) -> dict:
    """Case 1: exactly straight start at 3x the Euler load."""
    loads = Loads(forces=[(n - 1, (-3 * EULER, 0.0, 0.0))])
    res = solve_static(column(n), Supports.clamp_ends(n), loads)
    x_ref, y_ref = elastica_tip(3.0)
    return {
        "case": "euler_column_3x",
        "n_nodes": n,
        "stable": res.stable,
        "escapes": res.escapes,
        "iterations": res.iterations,
        "tip_x_over_L": res.positions[-1, 0] / LENGTH,
        "tip_x_over_L_elastica": x_ref,
        "tip_deflection_over_L": float(np.hypot(*res.positions[-1, 1:])) / LENGTH,
        "tip_deflection_over_L_elastica": y_ref,
        "lowest_eigenvalues": res.eigenvalues.tolist(),
    }


def euler_load(n: int) -> dict:
    """Case 2: the zero crossing of the straight column's lowest eigenvalue."""
    model, supports = column(n), Supports.clamp_ends(n)
    ratios, lowest = (0.9, 1.1), []
    for f in ratios:
        loads = Loads(forces=[(n - 1, (-f * EULER, 0.0, 0.0))])
        # hold it straight: without the stability check the solver stays on the symmetric state
        straight = solve_static(
            model, supports, loads, options=NewtonOptions(check_stability=False)
        )
        lowest.append(stability(model, straight.state, supports, loads, count=1).eigenvalues[0])
    crossing = ratios[0] + (ratios[1] - ratios[0]) * lowest[0] / (lowest[0] - lowest[1])
    return {
        "case": "euler_load_from_tangent_stiffness",
        "n_nodes": n,
        "lowest_eigenvalue_at_0.9": lowest[0],
        "lowest_eigenvalue_at_1.1": lowest[1],
        "critical_load_over_euler": crossing,
    }


def michell_ring(n: int) -> dict:
    """Case 3: a twisted ring just below and just above Michell's critical twist."""
    radius = 5.0
    phi = 2 * np.pi * np.arange(n) / n
    ring = Model.ring(
        np.c_[radius * np.cos(phi), radius * np.sin(phi), 0 * phi],
        bending_stiffness1=BENDING,
        bending_stiffness2=BENDING,
        twist_stiffness=TWIST,
        axial_stiffness=100 * YOUNG * np.pi * RADIUS**2,
    )
    critical = np.sqrt(3) * BENDING / (TWIST * radius)  # natural twist, 1/mm
    zero = np.zeros(n)
    out: dict = {"case": "michell_ring", "n_nodes": n, "critical_twist_per_mm": critical}
    for f in (0.9, 1.1):
        twisted = ring.with_natural(
            curvature1=zero, curvature2=zero, twist=np.full(n, f * critical)
        )
        res = stability(twisted, count=3)
        # an isotropic ring has one neutral mode (every material frame turned alike about the
        # centre line, no motion of the nodes); report the lowest mode that is not it
        scale = np.abs(res.eigenvalues).max()
        k = int(np.flatnonzero(np.abs(res.eigenvalues) > 1e-8 * scale)[0])
        mode = res.modes.displacements[k]
        out[f"stable_at_{f}"] = res.stable
        out[f"lowest_eigenvalue_at_{f}"] = float(res.eigenvalues[k])
        out[f"mode_out_of_plane_at_{f}"] = bool(np.abs(mode[:, 2]).max() > 0.5 * np.abs(mode).max())
    return out


def figure(n: int, path: Path) -> None:
    """The column buckled at 3x its Euler load against the elastica's tip, and the straight
    column's lowest eigenvalue against the load, crossing zero at the Euler load."""
    from rotomorph.plot.figure import new_figure, save_figure

    model, supports = column(n), Supports.clamp_ends(n)
    buckled = solve_static(model, supports, Loads(forces=[(n - 1, (-3 * EULER, 0.0, 0.0))]))
    ratios = np.linspace(0.5, 1.5, 9)
    lowest = []
    for f in ratios:
        loads = Loads(forces=[(n - 1, (-f * EULER, 0.0, 0.0))])
        straight = solve_static(
            model, supports, loads, options=NewtonOptions(check_stability=False)
        )
        lowest.append(stability(model, straight.state, supports, loads, count=1).eigenvalues[0])
    fig = new_figure(9.0, 3.8)
    left, right = fig.subplots(1, 2, width_ratios=[1.0, 1.2])
    p = buckled.positions / LENGTH
    lateral = np.hypot(p[:, 1], p[:, 2])
    left.plot([0.0, 1.0], [0.0, 0.0], color="0.7", lw=1, label="straight: an unstable equilibrium")
    left.plot(p[:, 0], lateral, "k-", lw=2, label="solve_static: leaves the saddle")
    tip = elastica_tip(3.0)
    left.plot([tip[0]], [tip[1]], "o", mfc="none", mec="C3", ms=9, label="elastica tip (exact)")
    left.set_aspect("equal")
    left.set_xlabel("x / L")
    left.set_ylabel("lateral deflection / L")
    left.set_title("Clamped–free column at 3 × its Euler load", fontsize=9)
    left.legend(fontsize=7, loc="upper right")
    left.grid(alpha=0.3)
    right.axhline(0.0, color="0.6", lw=1)
    right.axvline(1.0, color="C3", lw=1, ls="--", label="Euler load π²B/(4L²)")
    right.plot(
        ratios,
        1e6 * np.asarray(lowest),
        "ko-",
        ms=4,
        label="lowest eigenvalue, column held straight",
    )
    right.set_xlabel("compressive load / Euler load (–)")
    right.set_ylabel("lowest eigenvalue of the stiffness (µN/mm)")
    right.set_title("Loss of stability of the straight column", fontsize=9)
    right.legend(fontsize=7)
    right.grid(alpha=0.3)
    fig.set_layout_engine("constrained")
    save_figure(fig, path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=(__doc__ or "").strip().partition("\n")[0])
    parser.add_argument("--nodes", type=int, default=41, help="nodes per rod (>= 8)")
    parser.add_argument("--figure", type=Path, help="draw the column and its eigenvalue (PNG)")
    args = parser.parse_args(argv)
    for row in (buckled_column(args.nodes), euler_load(args.nodes), michell_ring(args.nodes)):
        print(json.dumps(row))
    if args.figure is not None:
        figure(args.nodes, args.figure)
    return 0


if __name__ == "__main__":
    main()  # always 0; not SystemExit, which would end a documentation build running it
