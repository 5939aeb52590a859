"""Rod basics
==========

Rod basics: build a filament, give it a natural curvature-twist field, support it, load it,
solve, and check the answer against the exact helix.

Run: ``python examples/rod_basics.py [--nodes N]``. Prints one JSON object per line.
"""

from __future__ import annotations

import argparse
import json

import numpy as np

from rotomorph.analysis.shape import fit_helix
from rotomorph.rod.model import Model
from rotomorph.solve.loads import Gravity, Loads, Supports
from rotomorph.solve.static import solve_static


def free_helix(n: int) -> dict:
    """A straight, free filament with kappa_bar = 0.5/mm, tau_bar = 0.3/mm becomes a helix."""
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
    result = solve_static(model)  # free-free
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


def drooping_cantilever(n: int) -> dict:
    """A clamped LCE filament (E = 29.67 MPa) sagging under its own weight and a tip load."""
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
    result = solve_static(model, Supports.clamp_ends(n), loads)
    return {
        "case": "cantilever",
        "n_nodes": n,
        "iterations": result.iterations,
        "tip_deflection_mm": float(-result.positions[-1, 2]),
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=101, help="nodes per filament")
    args = parser.parse_args(argv)
    for row in (free_helix(args.nodes), drooping_cantilever(args.nodes)):
        print(json.dumps(row))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
