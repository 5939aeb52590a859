"""Benchmark: set-up time of large lattices, from the design to the first Newton step.

For n × n lattices (default n = 25, 50, 100; ghost_nodes = 10) this times
``rotomorph.simulate_design(design, steps=1)`` until the solver is entered (the Newton solve
itself is replaced by an exception, so only set-up is measured: lattice, rod model, sparsity
pattern, ordering, perturbed start), and prints one JSON line per size with rod nodes, wall and
CPU seconds and microseconds per node. Linear set-up shows as a flat ``cpu_us_per_node``.

With ``--cli`` it times the whole command instead: ``rotomorph -v simulate DESIGN --steps 1 -o
…`` in a fresh process (imports, validation, set-up), until Newton's method starts (its first
debug record); the process is then stopped. Wall and CPU seconds of the child at that moment.

Run: ``python benchmarks/lattice_setup.py [--sizes 25 50 100] [--cli]`` (numba kernels warm:
run once).

Measured on the 2-core machine (CPU seconds; load average 5-10 from other work):

======  ========  ======================  ======================
n       nodes     before (cpu_us/node)    after (cpu_us/node)
======  ========  ======================  ======================
25      12 625    518                     87
50      51 500    298 (15.4 s)            34 (1.7 s)
100     208 000   157 (32.6 s)            40 (8.3 s)
======  ========  ======================  ======================

Where the time went: the print-program actuation solved the cross section for every vertex of
every printed line (435 400 rows for n = 100, 4 117 distinct: the lines repeat their print
states), now each distinct state once per section; the per-edge Python loops of the lattice
geometry, print programs, stencils and line look-ups are vectorised; the Hessian pattern is
found on node/twist unit pairs (5x fewer keys to sort).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import rotomorph.solve.static as static
from rotomorph.io.designfile import design_size, parse_design
from rotomorph.simulate.design import simulate_design


class _SolverEntered(Exception):
    pass


def _stop(*args: object, **kwargs: object) -> None:
    raise _SolverEntered


#: Runs the command line and writes a marker when Newton's method starts (its debug record).
_CHILD = """
import logging, sys
class Marker(logging.Handler):
    def emit(self, record):
        if record.getMessage().startswith("newton: start"):
            sys.stderr.write("SOLVER-ENTERED\\n")
            sys.stderr.flush()
newton = logging.getLogger("rotomorph.solve.newton")
newton.addHandler(Marker())
newton.setLevel(logging.DEBUG)
newton.propagate = False
from rotomorph.cli import main
sys.exit(main(sys.argv[1:]))
"""


def _child_cpu(pid: int) -> float:
    """User + system CPU seconds of a running process (Linux /proc)."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def cli_row(n: int) -> dict[str, object]:
    """Time ``rotomorph simulate`` of an n x n lattice from launch to its first Newton solve."""
    with tempfile.TemporaryDirectory(prefix="rotomorph-lattice-cli-") as tmp:
        design = Path(tmp) / "lattice.toml"
        design.write_text(f"schema_version = 1\n[lattice]\nn = {n}\n", encoding="utf-8")
        cmd = [sys.executable, "-c", _CHILD, "-v", "simulate", str(design), "--steps", "1"]
        t0 = time.perf_counter()
        proc = subprocess.Popen(
            [*cmd, "-o", str(Path(tmp) / "out"), "--no-movie"],
            stderr=subprocess.PIPE,
            stdout=subprocess.DEVNULL,
            text=True,
        )
        wall = cpu = float("nan")
        assert proc.stderr is not None
        for line in proc.stderr:
            if "SOLVER-ENTERED" in line:
                wall, cpu = time.perf_counter() - t0, _child_cpu(proc.pid)
                break
        proc.terminate()
        proc.wait()
    return {
        "case": "lattice-cli-to-solver",
        "n": n,
        "wall_s": round(wall, 2),
        "cpu_s": round(cpu, 2),
        "load_1min": round(os.getloadavg()[0], 2),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[25, 50, 100])
    parser.add_argument("--cli", action="store_true", help="time the whole command line")
    args = parser.parse_args()
    if args.cli:
        for n in args.sizes:
            print(json.dumps(cli_row(n)), flush=True)
        return
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
