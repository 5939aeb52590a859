"""Benchmark: set-up time of large lattices, from the design to the first Newton step.

For n × n lattices (default n = 25, 50, 100; ghost_nodes = 10) this times
``rotomorph.simulate_design(design, steps=1)`` until the solver is entered (the Newton solve
itself is replaced by an exception, so only set-up is measured: lattice, rod model, sparsity
pattern, ordering, perturbed start), and prints one JSON line per size with rod nodes, wall and
CPU seconds and microseconds per node. Linear set-up shows as a flat ``cpu_us_per_node``.

Run: ``python benchmarks/lattice_setup.py [--sizes 25 50 100]`` (numba kernels warm: run once).
"""

from __future__ import annotations

import argparse
import json
import time

import rotomorph.solve.static as static
from rotomorph.io.designfile import design_size, parse_design
from rotomorph.simulate.design import simulate_design


class _SolverEntered(Exception):
    pass


def _stop(*args: object, **kwargs: object) -> None:
    raise _SolverEntered


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[25, 50, 100])
    args = parser.parse_args()
    static.minimize = _stop  # type: ignore[assignment]
    for n in args.sizes:
        design = parse_design({"schema_version": 1, "lattice": {"n": n}})
        nodes = design_size(design).nodes
        wall, cpu = time.perf_counter(), time.process_time()
        try:
            simulate_design(design, steps=1)
        except _SolverEntered:
            pass
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        row = {
            "case": "lattice-setup",
            "n": n,
            "nodes": nodes,
            "wall_s": round(wall, 2),
            "cpu_s": round(cpu, 2),
            "cpu_us_per_node": round(1e6 * cpu / nodes, 1),
        }
        print(json.dumps(row), flush=True)


if __name__ == "__main__":
    main()
