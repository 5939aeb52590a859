"""Benchmark: a free straight rod relaxing into the exact helix.

Prints one JSON object per line: the helix case at N = 101, 1 001 and 10 001 nodes (wall time,
Newton iterations, final residual, helix errors, time per iteration) and one
``"case": "iteration_scaling"`` line with the scaling exponent of the time per Newton
iteration in N and its ratio, at N = 10 001, to one bare banded Cholesky factor + solve of the
same rod's Hessian (SciPy's ``cholesky_banded`` / ``cho_solve_banded``, measured here).

Run: ``python benchmarks/rod_helix.py [--repeat K]`` (after ``pip install -e .``).
"""

from __future__ import annotations

import argparse
import json
import time

import numpy as np
from scipy.linalg import cho_solve_banded, cholesky_banded

from rotomorph.analysis.shape import fit_helix
from rotomorph.rod.cases import HelixCase
from rotomorph.solve.loads import Loads, Supports
from rotomorph.solve.objective import RodObjective
from rotomorph.solve.static import solve_static


def _best(fn, repeat: int) -> tuple[float, object]:
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out


def bare_factorization_time(case: HelixCase, n: int, repeat: int) -> float:
    """Seconds for one cholesky_banded + cho_solve_banded of the rod's Hessian (upper form)."""
    model = case.model(n)
    res = solve_static(model)
    obj = RodObjective(model, res.state, Supports(), Loads())
    _, g, H = obj.evaluate(obj.vector(), True, True)
    ab = np.array(H.ab, order="F")
    ab[H.u] += 1e-8 * np.abs(ab[H.u]).max()  # the six rigid-body modes
    rhs = -g

    def run() -> None:
        c = cholesky_banded(ab, lower=False, check_finite=False)
        cho_solve_banded((c, False), rhs, check_finite=False)

    run()
    best, _ = _best(run, max(repeat, 20))
    return best


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=5, help="timing repeats (best is kept)")
    args = parser.parse_args(argv)
    case = HelixCase()
    solve_static(case.model(21))  # compile the kernels outside the timings
    sizes = [101, 1001, 10001]
    per_iteration = []
    for n in sizes:
        model = case.model(n)
        wall, res = _best(lambda m=model: solve_static(m), args.repeat if n < 10001 else 2)
        fit = fit_helix(res.positions)
        row = {
            "case": "helix",
            "n_nodes": n,
            "wall_s": wall,
            "newton_iterations": res.iterations,
            "factorizations": res.factorizations,
            "residual": res.residual,
            "radius_rel_err": abs(fit.radius - case.helix_radius) / case.helix_radius,
            "pitch_rel_err": abs(abs(fit.pitch) - case.helix_pitch) / case.helix_pitch,
            "time_per_iteration_s": wall / max(res.iterations, 1),
        }
        per_iteration.append(row["time_per_iteration_s"])
        print(json.dumps(row), flush=True)
    exponent = float(np.polyfit(np.log(sizes), np.log(per_iteration), 1)[0])
    bare = bare_factorization_time(case, sizes[-1], args.repeat)
    print(
        json.dumps(
            {
                "case": "iteration_scaling",
                "n_nodes": sizes[-1],
                "sizes": sizes,
                "time_per_iteration_s": per_iteration,
                "exponent": exponent,
                "bare_factor_solve_s": bare,
                "ratio_to_factorization": per_iteration[-1] / bare,
                "wall_s": float(sum(per_iteration)),
                "newton_iterations": None,
                "residual": None,
            }
        ),
        flush=True,
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
