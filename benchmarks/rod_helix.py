"""Benchmark: a free straight rod relaxing into the exact helix.

Prints one JSON object per line: the helix case at N = 101, 1 001 and 10 001 nodes (wall time,
Newton iterations, final residual, helix errors, time per iteration) and one
``"case": "iteration_scaling"`` line with the scaling exponent of the time per Newton
iteration in N and its ratio, at N = 10 001, to one bare banded Cholesky factor + solve of the
same rod's Hessian (SciPy's ``cholesky_banded`` / ``cho_solve_banded``, measured here).

The small end, where a solve is bound by per-iteration overhead rather than by its
factorizations: every case line also gives ``cpu_s`` (the least CPU time of this process over
the repeats: the cost on one core whatever the load) and ``cpu_per_solve_ms``; the
``lattice-3x3`` line is one solve of the expanding 3 x 3 lattice (129 nodes, 10 ghost nodes per
edge, the default ``program`` actuation at its end value, no contact) from its perturbed flat
printed state, with its lowest eigenvalue.

Run: ``python benchmarks/rod_helix.py [--repeat K] [--small]`` (after ``pip install -e .``;
``--small``: only the helix at N = 101 and the 3 x 3 lattice).
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


def _best_cpu(fn, repeat: int) -> float:
    """Least CPU seconds of ``repeat`` calls of ``fn`` (after the timed ones of ``_best``)."""
    best = np.inf
    for _ in range(repeat):
        c0 = time.process_time()
        fn()
        best = min(best, time.process_time() - c0)
    return float(best)


def lattice_case(repeat: int) -> dict:
    """One static solve of the expanding 3 x 3 lattice from its perturbed printed state."""
    from rotomorph.design.lattices import sinusoidal_lattice
    from rotomorph.lattice import get_actuation, lattice_model
    from rotomorph.lattice.actuation import default_stiffness
    from rotomorph.lattice.heating import perturbed_state, symmetry_breaking

    lat = sinusoidal_lattice(n=3, pattern="expanding")
    act = get_actuation("program")
    stiffness, fm = default_stiffness(act, None)
    lm = lattice_model(lat, stiffness=stiffness, filament_model=fm)
    initial = perturbed_state(lm.model, symmetry_breaking(lat, 1e-3 * lat.spacing, 0))
    model = act.natural(lm, act.end)

    def run():  # type: ignore[no-untyped-def]
        return solve_static(model, initial=initial)

    run()
    wall, res = _best(run, repeat)
    cpu = _best_cpu(run, repeat)
    return {
        "case": "lattice-3x3",
        "n_nodes": int(lat.network.n_nodes),
        "wall_s": wall,
        "cpu_s": cpu,
        "cpu_per_solve_ms": round(1e3 * cpu, 3),
        "newton_iterations": res.iterations,  # type: ignore[attr-defined]
        "factorizations": res.factorizations,  # type: ignore[attr-defined]
        "residual": res.residual,  # type: ignore[attr-defined]
        "stable": bool(res.stable),  # type: ignore[attr-defined]
        "lowest_eigenvalue": float(res.eigenvalues[0]),  # type: ignore[attr-defined]
        "time_per_iteration_s": cpu / max(res.iterations, 1),  # type: ignore[attr-defined]
    }


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
    parser.add_argument("--small", action="store_true", help="N = 101 and the 3 x 3 lattice")
    args = parser.parse_args(argv)
    case = HelixCase()
    solve_static(case.model(21))  # compile the kernels outside the timings
    sizes = [101] if args.small else [101, 1001, 10001]
    per_iteration = []
    for n in sizes:
        model = case.model(n)
        wall, res = _best(lambda m=model: solve_static(m), args.repeat if n < 10001 else 2)
        cpu = _best_cpu(lambda m=model: solve_static(m), args.repeat if n < 10001 else 2)
        fit = fit_helix(res.positions)
        row = {
            "case": "helix",
            "n_nodes": n,
            "wall_s": wall,
            "cpu_s": cpu,
            "cpu_per_solve_ms": round(1e3 * cpu, 3),
            "newton_iterations": res.iterations,
            "factorizations": res.factorizations,
            "residual": res.residual,
            "radius_rel_err": abs(fit.radius - case.helix_radius) / case.helix_radius,
            "pitch_rel_err": abs(abs(fit.pitch) - case.helix_pitch) / case.helix_pitch,
            "time_per_iteration_s": wall / max(res.iterations, 1),
        }
        per_iteration.append(row["time_per_iteration_s"])
        print(json.dumps(row), flush=True)
    print(json.dumps(lattice_case(args.repeat)), flush=True)
    if args.small:
        return 0
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
