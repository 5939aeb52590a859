"""The authors' Fig. 4 stretch sweep in rotomorph (JSON lines on stdout).

Their disMech set-up (:mod:`rotomorph.lattice.published`: 5 x 5 lattice of one-period sine
edges, A = l/4, 10 nodes per edge, their expand/shrink lists with limbs 29 and 30 in neither,
the logged run's E = 2e11 Pa, floor friction 0.4 and weight) swept over the 151 stretch values
-0.75 ... +0.75 by 0.01 by continuation: 0 -> -0.75 and 0 -> +0.75, every value starting from
the equilibrium of its neighbour nearer zero; the two ramps run side by side in a two-worker
process pool (``--workers 1``: one after the other). One line per value (``stretch``, ``wall_s``,
``characteristic_curvature`` in 1/mm, ``gaussian_sign``, the node rise above the floor
``floor_lift_mm``, ``stack_overlaps`` (filament segment pairs interpenetrating) and
``physical`` (certified stable and admissible)) and a total line (``case = "total"``:
``values``, ``wall_s`` and ``cpu_s`` of the whole sweep (CPU of both ramps, wherever they
ran), ``workers``, the authors' logged run for one value, ``authors_run_s`` = 706.4 s, and the
ratio). Kernels are compiled before the clock starts.

Run: ``python benchmarks/paper_sweep.py [--quick] [--workers N]`` (``--quick``: |stretch| <= 0.25
by 0.05, 11 values).
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor

from rotomorph.lattice.heating import heat_lattice
from rotomorph.lattice.published import (
    LOGGED_RUN_SECONDS,
    YOUNGS_MODULUS,
    published_actuation,
    published_gravity,
    published_lattice,
    published_sweep,
)


def main(quick: bool = False, workers: int = 2) -> None:
    # compile and load the kernels (contact, floor, friction) outside the timed sweep
    heat_lattice(
        published_lattice(),
        actuation=published_actuation(0.0, 0.01),
        steps=1,
        stiffness="paper",
        youngs_modulus=YOUNGS_MODULUS,
        contact=True,
        floor=True,
        friction=0.4,
        gravity=published_gravity(),
    )
    step, end = (0.05, 0.25) if quick else (0.01, 0.75)
    t0 = time.perf_counter()
    if workers > 1:
        with ProcessPoolExecutor(max_workers=2) as pool:
            sweep = published_sweep(step, end, executor=pool)
    else:
        sweep = published_sweep(step, end)
    wall = time.perf_counter() - t0
    for k, s in enumerate(sweep.stretch):
        print(
            json.dumps(
                {
                    "stretch": round(float(s), 4),
                    "wall_s": round(float(sweep.wall_time[k]), 4),
                    "characteristic_curvature": float(sweep.characteristic_curvature[k]),
                    "gaussian_sign": int(sweep.gaussian_sign[k]),
                    "floor_lift_mm": None
                    if sweep.floor_lift is None
                    else round(float(sweep.floor_lift[k]), 3),
                    "stack_overlaps": None
                    if sweep.stack_overlaps is None
                    else int(sweep.stack_overlaps[k]),
                    "physical": sweep.physical[k],
                }
            )
        )
    print(
        json.dumps(
            {
                "case": "total",
                "values": len(sweep.stretch),
                "wall_s": round(wall, 2),
                "cpu_s": round(sweep.cpu_time, 2),
                "workers": min(workers, 2),
                "authors_run_s": LOGGED_RUN_SECONDS,
                "authors_runs": len(sweep.stretch),
                "authors_sweep_s": round(LOGGED_RUN_SECONDS * len(sweep.stretch), 1),
                "speedup_vs_authors_sweep": round(
                    LOGGED_RUN_SECONDS * len(sweep.stretch) / wall, 1
                ),
                "first_saddle": sweep.first(-1),
                "first_dome": sweep.first(+1),
            }
        )
    )


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description="the authors' Fig. 4 stretch sweep")
    parser.add_argument("--quick", action="store_true")
    parser.add_argument("--workers", type=int, default=2, choices=(1, 2))
    args = parser.parse_args()
    main(quick=args.quick, workers=args.workers)
