"""Heating-ramp benchmark of sinusoidal lattices (JSON lines on stdout).

Paper lattices (5 x 5, 425 nodes, reading (b), x: 0 -> 0.75 in 16 steps): expanding,
contracting, dome, saddle, with area ratio, Gaussian sign, characteristic curvature, Newton
iterations per step and time per iteration. Then homogeneous lattices of 5 x 5, 10 x 10 and
20 x 20 nodes for the scaling of the time per Newton iteration with node count (fitted exponent
on the last line). Run: ``python benchmarks/lattice_ramp.py [--quick]``.
"""

from __future__ import annotations

import json
import sys
import time

import numpy as np

from rotomorph.design.lattices import sinusoidal_lattice
from rotomorph.lattice import heat_lattice


def _line(case: str, res, wall: float, **extra) -> dict:
    its = int(res.total_iterations)
    row = {
        "case": case,
        "n_nodes": int(res.lattice.network.n_nodes),
        "steps": len(res.parameter) - 1,
        "wall_s": round(wall, 4),
        "solve_s": round(float(res.wall_time.sum()), 4),
        "newton_iterations": its,
        "iterations_per_step": res.iterations[1:].tolist(),
        "time_per_iteration_ms": round(1e3 * float(res.wall_time.sum()) / max(its, 1), 3),
        "max_residual": float(res.residual.max()),
        "max_halvings": int(res.halvings.max()),
    }
    row.update(extra)
    return row


def main(quick: bool = False) -> None:
    heat_lattice(sinusoidal_lattice(n=2, ghost_nodes=2), steps=1)  # compile kernels first
    steps = 4 if quick else 16
    for pattern in ("expanding", "contracting", "dome", "saddle"):
        lat = sinusoidal_lattice(pattern=pattern)
        t0 = time.perf_counter()
        res = heat_lattice(lat, actuation="swapped", steps=steps)
        wall = time.perf_counter() - t0
        print(
            json.dumps(
                _line(
                    f"paper-{pattern}",
                    res,
                    wall,
                    pattern=pattern,
                    actuation=res.actuation,
                    area_ratio=round(float(res.area_ratio[-1]), 4),
                    gaussian_sign=int(res.gaussian_sign[-1]),
                    characteristic_curvature=round(float(res.characteristic_curvature[-1]), 5),
                    first_overlap_x=res.first_overlap(),
                )
            )
        )
    sizes, per_it = [], []
    for n in (5, 10) if quick else (5, 10, 20):
        lat = sinusoidal_lattice(n=n, pattern="expanding")
        t0 = time.perf_counter()
        res = heat_lattice(lat, actuation="swapped", steps=4)
        wall = time.perf_counter() - t0
        row = _line(f"scaling-{n}x{n}", res, wall, area_ratio=float(res.area_ratio[-1]))
        sizes.append(row["n_nodes"])
        per_it.append(row["time_per_iteration_ms"])
        print(json.dumps(row))
    slope = float(np.polyfit(np.log(sizes), np.log(per_it), 1)[0])
    print(
        json.dumps(
            {
                "case": "scaling-fit",
                "n_nodes": sizes,
                "time_per_iteration_ms": per_it,
                "exponent": round(slope, 3),
            }
        )
    )


if __name__ == "__main__":
    main(quick="--quick" in sys.argv)
